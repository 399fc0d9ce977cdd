#include "sim/run_task.h"

namespace recruit::sim {

ControllerSettings EffectiveSettings(const Task& task, const RunOptions& options) {
  ControllerSettings s = task.controller;
  if (options.estimator) s.estimator = *options.estimator;
  if (options.filter_model) s.filter_model = *options.filter_model;
  if (options.dT) s.dT = *options.dT;
  if (options.lambda) s.lambda = *options.lambda;
  return s;
}

nlohmann::json RunSummary::ToJson() const {
  nlohmann::json j;
  j["task"] = task;
  j["estimator"] = estimator;
  j["dT"] = dT;
  j["lambda"] = lambda;
  j["seed"] = seed;
  j["duration"] = duration;
  j["unit"] = unit;
  j["physics_steps"] = physics_steps;
  j["control_instants"] = control_instants;
  j["wall_seconds"] = wall_seconds;
  const RunMetrics& m = metrics;
  j["metrics"] = {{"tracking_rmse", m.tracking_rmse},
                  {"iae", m.iae},
                  {"overshoot", m.overshoot},
                  {"max_overshoot", m.max_overshoot},
                  {"settling_time", m.settling_time},
                  {"settled_fraction", m.settled_fraction},
                  {"oscillation", m.oscillation},
                  {"switching_rate", m.switching_rate},
                  {"estimator_rmse", m.estimator_rmse},
                  {"mean_nees", m.mean_nees},
                  {"estimator_within3", m.estimator_within3},
                  {"num_steps", m.num_steps}};
  nlohmann::json steps_json = nlohmann::json::array();
  for (const auto& s : steps) {
    steps_json.push_back({{"time", s.step.time},
                          {"from", s.step.from},
                          {"to", s.step.to},
                          {"end", s.step.end},
                          {"overshoot", s.overshoot},
                          {"settling_time", s.settling_time},
                          {"settled", s.settled}});
  }
  j["steps"] = steps_json;
  return j;
}

Result<RunSummary> RunTask(const Task& task, const RunOptions& options,
                           const std::vector<StepObserver*>& observers) {
  return Error{"RunTask: the closed loop is not built yet (waiting for plugin and control)"};
}

}  // namespace recruit::sim
