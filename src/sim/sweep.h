// Sweep: a grid of closed-loop runs (dT x lambda x estimator x seeds) spread over threads with
// TBB. Each run's seed comes from Rng::DeriveSeed(base_seed, seed index), so the results do not
// depend on the number of threads or the order runs finish in; runs with the same seed index
// share their random stream across grid cells (common random numbers). Every finished run is
// recorded in its own file under `<out>/runs/` (written atomically), so an interrupted sweep
// started again skips the runs it already has, if their input hash (SweepRun::input_hash) is the
// same.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "common/result.h"
#include "sim/run_metrics.h"
#include "sim/run_task.h"

namespace recruit::sim {

// One point of the plant axes (hardware and sensor parameters set through the task or its model,
// src/sweep/sweep_file.h): (axis name, value) in axis order. No values: the task as it is.
struct PlantPoint {
  std::vector<std::pair<std::string, double>> values;
};

struct SweepSpec {
  std::vector<double> dTs;
  std::vector<double> lambdas;
  std::vector<std::string> estimators;
  int seeds = 1;  // seed indices 0 .. seeds-1
  std::uint64_t base_seed = 1;
  std::optional<double> duration;  // override of the task's
  std::optional<std::string> filter_model;
  std::vector<PlantPoint> plant;         // outermost loop of the grid; empty = one point, no axes
  bool identify_missing_models = false;  // RunOptions::identify_missing_models of every run
};

struct SweepRun {
  int index = 0;  // position in the grid (plant point outermost, then dT, lambda, estimator, seed)
  int plant = 0;  // index into SweepSpec::plant
  std::vector<std::pair<std::string, double>> plant_values;
  double dT = 0, lambda = 0;
  std::string estimator;
  int seed_index = 0;
  std::uint64_t seed = 0;
  // Hash of everything else that determines the run's result (task and model file contents,
  // options, code version), set by the caller; a record is reused only if its hash is equal.
  std::string input_hash;
  // File-name-safe identity of the run, e.g. "dT0.5_l0.2_kalman_s3"; with plant axes prefixed by
  // the plant point's index, "p0007_dT0.5_l0.2_kalman_s3".
  std::string Key() const;
};

// The run options of one grid point: its estimator, dT, lambda and seed, the spec's duration and
// filter model (what `recruit sweep` and the Python `sweep` run each point with).
RunOptions RunOptionsFor(const SweepRun& run, const SweepSpec& spec);

Result<std::vector<SweepRun>> ExpandGrid(const SweepSpec& spec);

// Shard k of n (1 <= k <= n): the runs whose grid index i has i % n == k - 1. Round-robin, so
// every shard gets a like mix of plant points and dT; the shards partition the grid.
std::vector<SweepRun> ShardOf(const std::vector<SweepRun>& grid, int k, int n);
// Parses "K/N" (1 <= K <= N <= 100000).
Result<std::pair<int, int>> ParseShard(const std::string& text);
// Identity of a whole sweep (every run's key and input hash, in grid order): shards of the same
// sweep carry the same id, and merge refuses shards of another.
std::string SweepId(const std::vector<SweepRun>& grid);

// What the sweep runs for one grid point (RunTask in production, a fake in tests).
using SweepRunFn = std::function<Result<RunSummary>(const SweepRun&)>;

struct SweepOutcome {
  std::vector<RunSummary> runs;  // in grid order
  int executed = 0;              // runs made now
  int reused = 0;                // runs read back from <out>/runs
};

// Runs every grid point not yet recorded under `out_dir`/runs on `threads` threads (0 = all
// cores). `progress(done, total)` is called from worker threads (serialised) after each run.
// Each finished run also appends one summary line to `out_dir`/progress.log (tail -f it).
Result<SweepOutcome> RunSweep(const std::vector<SweepRun>& grid, const std::string& out_dir,
                              const SweepRunFn& run, int threads,
                              const std::function<void(int, int)>& progress = {});

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
  std::array<double, kMetricCount> mean{}, sd{};
  double Mean(double RunMetrics::*field) const { return mean.at(MetricIndex(field)); }
  double Sd(double RunMetrics::*field) const { return sd.at(MetricIndex(field)); }
  bool meets = false;
  double margin = 0;  // min(max_overshoot - overshoot, settled - min_settled); >= 0 iff meets
  // Over seeds: each seed's own margin (same formula on its run alone), how many meet, and the
  // standard error of their mean (the spread the confidence in the report comes from).
  int seeds_meeting = 0;
  double margin_se = 0;
};

// Cells in grid order; runs are told apart by (dT, lambda, estimator).
std::vector<CellStats> Aggregate(const std::vector<RunSummary>& runs,
                                 const TrackingCriterion& criterion);
// The same with plant points: runs[i] was made for grid[i].
std::vector<CellStats> Aggregate(const std::vector<SweepRun>& grid,
                                 const std::vector<RunSummary>& runs,
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
Status WriteSweepReport(const std::vector<CellStats>& cells, const TrackingCriterion& criterion,
                        const std::string& out_dir, const std::string& title);

// RunSummary <-> JSON for the per-run record files.
Result<RunSummary> RunSummaryFromJson(const nlohmann::json& j);

}  // namespace recruit::sim
