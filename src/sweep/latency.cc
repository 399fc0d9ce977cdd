#include "sweep/latency.h"

#include <mujoco/mujoco.h>

#include <cmath>
#include <vector>

#include "common/mujoco_load.h"
#include "common/mujoco_ptr.h"

namespace recruit::sweep {

double DelayLoopOvershoot(double a) {
  constexpr double h = 1e-3;
  constexpr int delay = 1000;  // steps per unit delay
  const int n = 80 * delay;
  std::vector<double> y(n + 1, 0.0);
  double peak = 0;
  for (int i = 0; i < n; ++i) {
    const double yd = i >= delay ? y[i - delay] : 0.0;
    y[i + 1] = y[i] + h * a * (1 - yd);
    peak = std::max(peak, y[i + 1]);
  }
  return peak - 1;
}

double DelayLoopGainForOvershoot(double overshoot) {
  double lo = 1e-3, hi = M_PI / 2;
  for (int it = 0; it < 40; ++it) {
    const double mid = 0.5 * (lo + hi);
    (DelayLoopOvershoot(mid) > overshoot ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

Result<double> ForceLatency(const sim::Task& task) {
  auto model = LoadModel(task.model_path);
  if (!model.ok()) return Error{model.error(), model.code()};
  mjModel* m = model->get();
  if (task.timestep > 0) m->opt.timestep = task.timestep;
  const int act = mj_name2id(m, mjOBJ_ACTUATOR, task.agonist.c_str());
  if (act < 0) return Error{"force latency: no actuator '" + task.agonist + "'"};
  DataPtr data(mj_makeData(m));
  mjData* d = data.get();
  const double horizon = 30;
  std::vector<std::pair<double, double>> trace;
  trace.reserve(static_cast<size_t>(horizon / m->opt.timestep) + 1);
  while (d->time < horizon) {
    d->ctrl[act] = 1.0;
    mj_step(m, d);
    trace.emplace_back(d->time, std::abs(d->actuator_force[act]));
  }
  const double final_force = trace.back().second;
  if (!(final_force > 0))
    return Error{"force latency: the bundle '" + task.agonist + "' pulls 0 N"};
  for (const auto& [t, f] : trace) {
    if (f >= 0.5 * final_force) return t;
  }
  return Error{"force latency: no half-force crossing"};
}

}  // namespace recruit::sweep
