// `recruit export --sweep DIR`: the sampling period and gain a sweep's report recommends for the
// task (sweep::Recommend over the sweep's table.csv: per lambda, the shortest dT tried that meets
// the tracking criterion; of those, the shortest dT, then the largest margin). A sweep with plant
// axes recommends per plant point: `--plant-point K` exports for the sweep's plant at point K
// (the task and model with that point's values applied, as the sweep ran it).
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/result.h"
#include "sim/task.h"

namespace recruit::exporter {

struct SweepSettings {
  double dT = 0, lambda = 0;
  std::string why;  // one line: the margin and the seeds
  // With plant axes: the plant point's index and values, and its task (the sweep's task with the
  // point's values applied, its model the point's edited model when an axis edits the model).
  int plant_point = -1;
  std::vector<std::pair<std::string, double>> plant_values;
  std::optional<sim::Task> plant_task;
};

// From `dir` (a `recruit sweep` output folder of this task: its table.md names the task) for
// `estimator`; `plant_point` (>= 0) the plant point of a sweep with plant axes (-1: none).
// Refused: another task's sweep, a sweep with plant axes without a plant point (and a plant point
// without plant axes, or out of range), no cell of the estimator meeting the criterion.
Result<SweepSettings> SweepChoice(const std::string& dir, const sim::Task& task,
                                  const std::string& estimator, int plant_point = -1);

}  // namespace recruit::exporter
