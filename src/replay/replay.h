// Replay of a bench log on the simulated plant (docs/replay.md): the task's plant is driven
// open loop by the log's recorded broadcasts, one control instant after another, and what a rig
// records is read off it at each instant: each bundle's load-cell reading (the task's sensor
// model, before the instant's broadcast, as `recruit simulate` samples it) and each joint angle
// (after the instant's physics step, as `recruit simulate` writes its rows). Several seeds give
// the plant's own spread under the same broadcasts.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/result.h"
#include "estimation/bench_log.h"
#include "sim/task.h"

namespace recruit::replay {

// One compared quantity: a bundle's force or a joint's angle.
struct Signal {
  std::string name;  // "<bundle>.sensed_force", "angle" or "<joint>.angle" (the log's column)
  std::string unit;  // "N" or "rad"
  int bundle = -1;   // the plant's bundle (force signals)
  int joint = -1;    // the plant's driven joint; -1 with bundle -1: the task's main joint
  std::vector<double> recorded;  // the log's value at each control instant
};

// The signals the log and the task's plant share, and which log bundle drives each plant
// bundle. Errors: a bundle of the plant the log has no broadcasts for, or a log bundle the
// plant does not have (both named with what the other side has).
struct ReplayPlan {
  std::vector<Signal> signals;
  std::vector<int> log_bundle;              // by plant bundle: its index in BenchLog::bundles
  double dT = 0;                            // the log's control period, s
  std::vector<std::string> ignored_angles;  // the log's angle columns the plant has no joint for
};
Result<ReplayPlan> PlanReplay(const sim::Task& task, const estimation::BenchLog& log);

// One replay with the plant's and the load cells' streams seeded by `seed` (the streams of
// `recruit simulate --seed`, so a log simulated with that seed is reproduced exactly): by
// signal, the value at each control instant.
Result<std::vector<std::vector<double>>> ReplayOnce(const sim::Task& task,
                                                    const estimation::BenchLog& log,
                                                    const ReplayPlan& plan, std::uint64_t seed);

}  // namespace recruit::replay
