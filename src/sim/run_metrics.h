// RunMetrics: the scores of one closed-loop run, and kMetricFields, the one table of its fields.
// The table drives the summary JSON's "metrics" object (writer and reader), the sweep's per-cell
// columns (table.csv, sweep/table.h CellStats) and the Python package's metric names and aggregate
// columns: a metric added to the struct and to the table appears in all of them
// (tests/sim/run_metrics_test.cc fails if the struct has a field the table lacks).
#pragma once

#include <array>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace recruit::sim {

struct RunMetrics {
  double tracking_rmse = 0;      // N or rad
  double iae = 0;                // N s or rad s
  double overshoot = 0;          // mean over steps, fraction of the step size
  double max_overshoot = 0;      // largest over steps
  double settling_time = 0;      // mean over steps, s (an unsettled step counts its whole hold)
  double settled_fraction = 0;   // steps that settled within their hold
  double oscillation = 0;        // excess total variation, see metrics.h
  double switching_rate = 0;     // unit transitions per unit per second (all bundles)
  double estimator_rmse = 0;     // units, at control instants (agonist)
  double mean_nees = 0;          // on-count NEES at control instants (agonist); NaN: no variance
  double estimator_within3 = 0;  // fraction of control instants with |n^ - n| <= 3
  int num_steps = 0;
};

// One field of RunMetrics. Exactly one of `real` and `count` is set.
struct MetricField {
  const char* name;  // key in the summary JSON's "metrics", Python column
  double RunMetrics::*real;
  int RunMetrics::*count;
  const char* unit;  // unit or meaning
  // NaN means "not defined" (written as JSON null); the sweep's cell mean leaves NaN runs out.
  bool may_be_nan;
  // The sweep's per-cell column of its mean over seeds (table.csv, Python aggregate);
  // nullptr: not in the sweep's table.
  const char* cell_mean;
  // Also the sample standard deviation over seeds, in column <name>_sd after the mean.
  bool cell_sd;
};

// In the order of the sweep table's columns; the JSON object's keys are sorted by name.
inline constexpr std::array<MetricField, 12> kMetricFields{{
    {"overshoot", &RunMetrics::overshoot, nullptr, "fraction of the step, mean over steps", false,
     "overshoot_mean", true},
    {"settling_time", &RunMetrics::settling_time, nullptr, "s, mean over steps", false,
     "settling_time_mean", false},
    {"settled_fraction", &RunMetrics::settled_fraction, nullptr, "fraction of steps", false,
     "settled_fraction", false},
    {"tracking_rmse", &RunMetrics::tracking_rmse, nullptr, "N or rad", false, "tracking_rmse_mean",
     false},
    {"iae", &RunMetrics::iae, nullptr, "N s or rad s", false, "iae_mean", false},
    {"oscillation", &RunMetrics::oscillation, nullptr, "excess total variation", false,
     "oscillation_mean", false},
    {"switching_rate", &RunMetrics::switching_rate, nullptr, "transitions per unit per s", false,
     "switching_rate_mean", false},
    {"estimator_rmse", &RunMetrics::estimator_rmse, nullptr, "units", false, "estimator_rmse_mean",
     false},
    {"mean_nees", &RunMetrics::mean_nees, nullptr, "on-count NEES; NaN: no variance", true,
     "mean_nees_mean", false},
    {"estimator_within3", &RunMetrics::estimator_within3, nullptr, "fraction of instants", false,
     "estimator_within3_mean", false},
    {"max_overshoot", &RunMetrics::max_overshoot, nullptr, "fraction of the step, largest", false,
     nullptr, false},
    {"num_steps", nullptr, &RunMetrics::num_steps, "reference steps", false, nullptr, false},
}};
inline constexpr std::size_t kMetricCount = kMetricFields.size();

// The index in kMetricFields of a real-valued field (kMetricCount if it is not there).
constexpr std::size_t MetricIndex(double RunMetrics::*field) {
  for (std::size_t i = 0; i < kMetricCount; ++i) {
    if (kMetricFields[i].real == field) return i;
  }
  return kMetricCount;
}

// The value of field `f` of `m` (a count as a double).
double MetricValue(const RunMetrics& m, const MetricField& f);
// Sets field `f` of `m` (a count rounded to the nearest whole number).
void SetMetric(RunMetrics& m, const MetricField& f, double value);

// The summary JSON's "metrics" object: every field by name (NaN as null).
nlohmann::json MetricsToJson(const RunMetrics& m);
// Its inverse; throws nlohmann::json::exception naming a missing or mistyped key.
RunMetrics MetricsFromJson(const nlohmann::json& j);

// The sweep's per-cell metric columns, in table order (the means, and <name>_sd after those
// that have one).
std::vector<std::string> CellMetricColumns();

}  // namespace recruit::sim
