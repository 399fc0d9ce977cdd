// A sweep's runs per grid cell (all seeds of one plant point, dT, lambda, estimator) against a
// stated tracking criterion, and the tables written from them: table.csv, table.md and the
// stability map's data (stability.dat).
#pragma once

#include <array>
#include <string>
#include <utility>
#include <vector>

#include "common/result.h"
#include "sim/run_metrics.h"
#include "sweep/grid.h"

namespace recruit::sweep {

// A stated tracking criterion for one grid cell (all seeds of one dT, lambda, estimator).
struct TrackingCriterion {
  double max_overshoot = 0.10;  // mean step overshoot, fraction of the step
  double min_settled = 0.90;    // fraction of steps that settle within the 10 % band
};

// One grid cell aggregated over seeds.
struct CellStats {
  int plant = 0;
  std::vector<std::pair<std::string, double>> plant_values;
  double dT = 0, lambda = 0;
  std::string estimator;
  int seeds = 0;
  // Per field of kMetricFields (sim/run_metrics.h), over seeds: the mean (of the finite values
  // for a field that may be NaN; NaN if none is) and the sample standard deviation.
  std::array<double, sim::kMetricCount> mean{}, sd{};
  double Mean(double sim::RunMetrics::*field) const { return mean.at(sim::MetricIndex(field)); }
  double Sd(double sim::RunMetrics::*field) const { return sd.at(sim::MetricIndex(field)); }
  // The criterion on the means (margin >= 0), and no run past a datasheet limit: a design that
  // breaks its own wires' limits is never recommended.
  bool meets = false;
  double margin = 0;         // min(max_overshoot - overshoot, settled - min_settled)
  int runs_past_limits = 0;  // runs in which a wire passed its datasheet limits
  // Over seeds: each seed's own margin (same formula on its run alone), how many meet, and the
  // standard error of their mean (the spread the confidence in the report comes from).
  int seeds_meeting = 0;
  double margin_se = 0;
};

// Cells in grid order; runs are told apart by (dT, lambda, estimator).
std::vector<CellStats> Aggregate(const std::vector<sim::RunSummary>& runs,
                                 const TrackingCriterion& criterion);
// The same with plant points: runs[i] was made for grid[i].
std::vector<CellStats> Aggregate(const std::vector<SweepRun>& grid,
                                 const std::vector<sim::RunSummary>& runs,
                                 const TrackingCriterion& criterion);

// The columns of table.csv and of the Python aggregate, plant axes left out: dT, lambda,
// estimator, seeds, the metric columns (CellMetricColumns()), meets_criterion, margin.
std::vector<std::string> CellColumns();
// A cell's values of the metric columns, in their order.
std::vector<double> CellMetricValues(const CellStats& c);

// Writes table.csv, table.md (with a column per plant axis when there are plant points),
// and, without plant axes, stability.dat (the map's data: `recruit sweep` draws stability.png from
// it with the plot module, sweep::StabilityMapOptions) into `out_dir`. The files depend only on
// the runs' results. Any failed write (full disk) is an error.
Status WriteTables(const std::vector<CellStats>& cells, const TrackingCriterion& criterion,
                   const std::string& out_dir, const std::string& title);

}  // namespace recruit::sweep
