// Reproduces the paper's Fig. 4 on models/isometric_bench.xml: all units switched on at t = 1 s,
// off at t = t_off, and prints CSV (time, tension, on count, mean temperature, mean xi) to stdout.
// Usage: sma_fig4_step [model.xml] [t_off=12] [t_end=20]
#include <cstdio>
#include <cstdlib>
#include <string>

#include "plugin/sma_plugin.h"

int main(int argc, char** argv) {
  const std::string path = argc > 1 ? argv[1] : RECRUIT_SOURCE_DIR "/models/isometric_bench.xml";
  const double t_off = argc > 2 ? std::atof(argv[2]) : 12.0;
  const double t_end = argc > 3 ? std::atof(argv[3]) : 20.0;
  char err[1000] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, err, sizeof err);
  if (m == nullptr) {
    std::fprintf(stderr, "%s: %s\n", path.c_str(), err);
    return 1;
  }
  auto plugin = recruit::sma::SmaPlugin::Create(m);
  if (!plugin.ok()) {
    std::fprintf(stderr, "%s: %s\n", path.c_str(), plugin.error().c_str());
    mj_deleteModel(m);
    return 1;
  }
  const auto& p = **plugin;
  mjData* d = mj_makeData(m);
  p.Reset(d, 1);
  const int b = 0;
  std::printf("time,tension,on,mean_temperature,mean_xi,load_cell_force\n");
  bool on = false, off = false;
  const int jnt = mj_name2id(m, mjOBJ_JOINT, "load_cell");
  while (d->time < t_end - 1e-9) {
    if (!on && d->time >= 1.0 - 1e-9) {
      (void)p.Broadcast(d, b, 1.0, 0.0);
      on = true;
    }
    if (!off && d->time >= t_off - 1e-9) {
      (void)p.Broadcast(d, b, 0.0, 1.0);
      off = true;
    }
    recruit::sma::Step(m, d, p);
    const int step = static_cast<int>(d->time / m->opt.timestep + 0.5);
    if (step % 10 == 0) {
      const double lc = jnt >= 0 ? -m->jnt_stiffness[jnt] * d->qpos[m->jnt_qposadr[jnt]] : 0;
      std::printf("%.3f,%.5f,%d,%.4f,%.6f,%.5f\n", d->time, p.Force(d, b), p.OnCount(d, b),
                  p.MeanTemperature(d, b), p.MeanXi(d, b), lc);
    }
  }
  mj_deleteData(d);
  mj_deleteModel(m);
  return 0;
}
