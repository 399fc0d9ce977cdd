// `recruit replay`'s work without the files: the replays over the seeds, the comparison of each
// signal, and what is written (JSON report, CSV of the signals, the figure as plot data).
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/result.h"
#include "estimation/bench_log.h"
#include "plot/figure.h"
#include "replay/compare.h"
#include "replay/replay.h"
#include "sim/task.h"

namespace recruit::replay {

struct ReplayOptions {
  int num_seeds = 16;              // S >= 3 replays
  std::uint64_t first_seed = 101;  // seeds first_seed .. first_seed + S - 1 (apart from a
                                   // simulated log's usual seeds)
  double max_lag = -1;             // s; < 0: 5 control periods
  Criterion criterion;
};

struct ReplayResult {
  std::string log_path, task_source, task_name;
  double dT = 0;
  std::vector<double> time;  // the log's control instants
  ReplayPlan plan;
  std::vector<std::vector<std::vector<double>>> runs;  // [signal][seed][k]
  std::vector<SignalComparison> comparisons;           // by signal
  ReplayOptions options;
  bool flagged = false;  // any signal
};

Result<ReplayResult> RunReplay(const sim::Task& task, const estimation::BenchLog& log,
                               const ReplayOptions& options);

nlohmann::json ReportJson(const ReplayResult& r);
// time, then per signal <name>.recorded, <name>.simulated_mean, <name>.simulated_sd.
std::string SignalsCsv(const ReplayResult& r);
// One panel per signal: the runs' range (band), their mean and the recorded signal; angles in
// degrees.
plot::Figure ReplayFigure(const ReplayResult& r);

}  // namespace recruit::replay
