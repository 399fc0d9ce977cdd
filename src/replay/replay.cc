#include "replay/replay.h"

#include <algorithm>

#include "common/rng.h"
#include "common/short_text.h"
#include "sim/force_sensor.h"
#include "sim/plant.h"

namespace recruit::replay {
namespace {

// The load cells' noise streams: Rng::DeriveSeed(seed, kSensorStream + bundle), as RunTask
// derives them (sim/run_task.cc), so that a replay with a log's own seed reproduces it.
constexpr std::uint64_t kSensorStream = 0x5E750000;

std::string Names(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return ShortText(s, 200);
}

}  // namespace

Result<ReplayPlan> PlanReplay(const sim::Task& task, const estimation::BenchLog& log) {
  auto plant_or = sim::Plant::Create(task, /*drawn=*/false);
  if (!plant_or.ok()) return plant_or.failure();
  const sim::Plant& plant = **plant_or;
  ReplayPlan plan;
  plan.dT = log.dT;
  std::vector<std::string> log_names, plant_names;
  for (const auto& b : log.bundles) log_names.push_back(b.name);
  for (int i = 0; i < plant.num_bundles(); ++i) plant_names.push_back(plant.bundle_name(i));
  for (int i = 0; i < plant.num_bundles(); ++i) {
    const auto it = std::find(log_names.begin(), log_names.end(), plant_names[i]);
    if (it == log_names.end()) {
      return Error{log.path + ": no columns for the task's bundle '" + plant_names[i] + "' (" +
                   plant_names[i] + ".p_on, .p_off, .sensed_force); the log has bundles " +
                   Names(log_names)};
    }
    plan.log_bundle.push_back(static_cast<int>(it - log_names.begin()));
    plan.signals.push_back({plant_names[i] + ".sensed_force", "N", i, -1,
                            log.bundles[plan.log_bundle.back()].sensed_force});
  }
  for (const auto& name : log_names) {
    if (std::find(plant_names.begin(), plant_names.end(), name) == plant_names.end()) {
      return Error{log.path + ": bundle '" + name + "' is not driven by the task (" + task.source +
                   "); its bundles: " + Names(plant_names)};
    }
  }
  for (const auto& a : log.angles) {
    int joint = -2;  // none
    if (a.name == "angle") {
      if (plant.has_joint()) joint = -1;
    } else {
      for (int j = 1; j < plant.num_joints(); ++j) {
        if (plant.joint_name(j) == a.name) joint = j;
      }
    }
    if (joint == -2) {
      plan.ignored_angles.push_back(a.name == "angle" ? "angle" : a.name + ".angle");
      continue;
    }
    plan.signals.push_back(
        {a.name == "angle" ? "angle" : a.name + ".angle", "rad", -1, joint, a.value});
  }
  return plan;
}

Result<std::vector<std::vector<double>>> ReplayOnce(const sim::Task& task,
                                                    const estimation::BenchLog& log,
                                                    const ReplayPlan& plan, std::uint64_t seed) {
  auto plant_or = sim::Plant::Create(task, /*drawn=*/false);
  if (!plant_or.ok()) return plant_or.failure();
  sim::Plant& plant = **plant_or;
  plant.Reset(seed);
  const int nb = plant.num_bundles();
  std::vector<sim::ForceSensor> sensors;
  for (int i = 0; i < nb; ++i) {
    auto s = sim::ForceSensor::Create(task.sensor, Rng::DeriveSeed(seed, kSensorStream + i));
    if (!s.ok()) return s.failure().In(task.source + ".sensor: ");
    sensors.push_back(std::move(s).value());
  }
  const int n = log.size();
  std::vector<std::vector<double>> out(plan.signals.size(), std::vector<double>(n));
  const double h = plant.timestep();
  std::vector<double> sensed(nb);
  for (int k = 0; k < n;) {
    // The control instants at k dT (the log's period), as RunTask finds them.
    const bool instant = plant.time() + 0.5 * h >= k * plan.dT;
    if (instant) {
      // Every load cell first, then every broadcast, as RunTask's control instant does.
      for (int i = 0; i < nb; ++i) sensed[i] = sensors[i].SampleAndHold(plant.Force(i));
      for (int i = 0; i < nb; ++i) {
        const estimation::BenchLog::Bundle& b = log.bundles[plan.log_bundle[i]];
        if (Status st = plant.Broadcast(i, b.p_on[k], b.p_off[k]); !st.ok()) {
          return st.failure().In(log.path + ":" + std::to_string(log.line[k]) + ": ");
        }
      }
    }
    plant.Step();
    if (Status st = plant.CheckFinite(); !st.ok()) return st.failure().In(task.source + ": ");
    if (!instant) continue;
    for (size_t s = 0; s < plan.signals.size(); ++s) {
      const Signal& sig = plan.signals[s];
      out[s][k] = sig.bundle >= 0 ? sensed[sig.bundle]
                  : sig.joint < 0 ? plant.angle()
                                  : plant.JointAngle(sig.joint);
    }
    ++k;
  }
  return out;
}

}  // namespace recruit::replay
