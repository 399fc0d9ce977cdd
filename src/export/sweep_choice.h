// `recruit export --sweep DIR`: the sampling period and gain a sweep's report recommends for the
// task (sweep::Recommend over the sweep's table.csv: per lambda, the shortest dT tried that meets
// the tracking criterion; of those, the shortest dT, then the largest margin).
#pragma once

#include <string>

#include "common/result.h"
#include "sim/task.h"

namespace recruit::exporter {

struct SweepSettings {
  double dT = 0, lambda = 0;
  std::string why;  // one line: the margin and the seeds
};

// From `dir` (a `recruit sweep` output folder of this task: its table.md names the task) for
// `estimator`. Refused: another task's sweep, a sweep with plant axes (its recommendations are
// per plant point), no cell of the estimator meeting the criterion.
Result<SweepSettings> SweepChoice(const std::string& dir, const sim::Task& task,
                                  const std::string& estimator);

}  // namespace recruit::exporter
