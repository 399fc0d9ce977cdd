// Reproduces the paper's Fig. 4 on models/isometric_bench.xml: all units switched on at t = 1 s,
// off at t = t_off, and prints CSV (time, tension, on count, mean temperature, mean xi, load
// cell force) to stdout and the step figures (peak force, time to 75 %, settling time into
// +-5 %, relaxation time to 5 %) to stderr.
// Usage: sma_fig4_step [model.xml] [t_off=12] [t_end=20]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "plugin/sma_host.h"

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
  auto plugin = recruit::sma::SmaHost::Create(m);
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
  std::vector<double> ts, fs;
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
    mj_step(m, d);
    ts.push_back(d->time);
    fs.push_back(p.Force(d, b));
    const int step = static_cast<int>(d->time / m->opt.timestep + 0.5);
    if (step % 10 == 0) {
      const double lc = jnt >= 0 ? -m->jnt_stiffness[jnt] * d->qpos[m->jnt_qposadr[jnt]] : 0;
      std::printf("%.3f,%.5f,%d,%.4f,%.6f,%.5f\n", d->time, p.Force(d, b), p.OnCount(d, b),
                  p.MeanTemperature(d, b), p.MeanXi(d, b), lc);
    }
  }
  // Step figures, times measured from the switching instants.
  double peak = 0, t75 = -1, settle = 0, relax = -1;
  for (size_t i = 0; i < ts.size(); ++i) {
    if (ts[i] <= t_off + 1e-9) peak = fs[i];  // force just before switching off
  }
  for (size_t i = 0; i < ts.size(); ++i) {
    if (ts[i] <= 1.0 || ts[i] > t_off + 1e-9) continue;
    if (t75 < 0 && fs[i] >= 0.75 * peak) t75 = ts[i] - 1.0;
    if (std::abs(fs[i] - peak) > 0.05 * peak) settle = ts[i] - 1.0;
  }
  for (size_t i = 0; i < ts.size(); ++i) {
    if (ts[i] > t_off + 1e-9 && relax < 0 && fs[i] <= 0.05 * peak) relax = ts[i] - t_off;
  }
  std::fprintf(stderr,
               "peak force %.2f N (after %.0f s on); 75 %% at %.2f s; within +-5 %% after %.2f s; "
               "below 5 %% %.2f s after switching off; settled unit force %.3f N\n",
               peak, t_off - 1.0, t75, settle, relax, p.SettledUnitForce(b));
  mj_deleteData(d);
  plugin.value().reset();
  mj_deleteModel(m);
  return 0;
}
