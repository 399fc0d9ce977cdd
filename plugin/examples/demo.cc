// The demo of plugin/README.md: load the isometric bench, switch half the units on, step 3 s,
// print the ground truth. Built as sma_demo and run by ctest (plugin_demo).
#include <cstdio>

#include "plugin/sma_host.h"

int main() {
  char err[1000] = "";
  mjModel* m =
      mj_loadXML(RECRUIT_SOURCE_DIR "/models/isometric_bench.xml", nullptr, err, sizeof err);
  if (m == nullptr) {
    std::fprintf(stderr, "isometric_bench.xml: %s\n", err);
    return 1;
  }
  auto plugin = recruit::sma::SmaHost::Create(m);
  if (!plugin.ok()) {
    std::fprintf(stderr, "isometric_bench.xml: %s\n", plugin.error().c_str());
    mj_deleteModel(m);
    return 1;
  }
  const recruit::sma::SmaHost& sma = **plugin;
  const int b = sma.BundleIndex("bundle");
  mjData* d = mj_makeData(m);
  sma.Reset(d, /*seed=*/42);                           // all units off, at ambient
  recruit::Status st = sma.Broadcast(d, b, 0.5, 0.0);  // each off unit turns on with p = 0.5
  if (!st.ok()) std::fprintf(stderr, "%s\n", st.error().c_str());
  while (d->time < 3.0) mj_step(m, d);  // mj_step, then the units advance
  std::printf(
      "t=%.1f s: %d of %d units on, tension %.2f N (%.2f N per settled unit), "
      "mean temperature %.1f C, heat %.2f\n",
      d->time, sma.OnCount(d, b), sma.num_units(b), sma.Force(d, b), sma.SettledUnitForce(b),
      sma.MeanTemperature(d, b), sma.Heat(d, b));
  const bool ok = st.ok() && sma.Force(d, b) > 0;
  mj_deleteData(d);
  plugin.value().reset();  // unregister before the model goes
  mj_deleteModel(m);
  return ok ? 0 : 1;
}
