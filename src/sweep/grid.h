// Sweep: a grid of closed-loop runs (dT x lambda x estimator x seeds) spread over threads with
// TBB. Each run's seed comes from Rng::DeriveSeed(base_seed, seed index), so the results do not
// depend on the number of threads or the order runs finish in; runs with the same seed index
// share their random stream across grid cells (common random numbers). Every finished run is
// recorded in its own file under `<out>/runs/` (written atomically), so an interrupted sweep
// started again skips the runs it already has, if their input hash (SweepRun::input_hash) is the
// same.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "common/result.h"
#include "sim/run_metrics.h"
#include "sim/run_task.h"

namespace recruit::sweep {

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
sim::RunOptions RunOptionsFor(const SweepRun& run, const SweepSpec& spec);

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
using SweepRunFn = std::function<Result<sim::RunSummary>(const SweepRun&)>;

struct SweepOutcome {
  std::vector<sim::RunSummary> runs;  // in grid order
  int executed = 0;                   // runs made now
  int reused = 0;                     // runs read back from <out>/runs
};

// Runs every grid point not yet recorded under `out_dir`/runs on `threads` threads (0 = all
// cores). `progress(done, total)` is called from worker threads (serialised) after each run.
// Each finished run also appends one summary line to `out_dir`/progress.log (tail -f it).
Result<SweepOutcome> RunSweep(const std::vector<SweepRun>& grid, const std::string& out_dir,
                              const SweepRunFn& run, int threads,
                              const std::function<void(int, int)>& progress = {});

// RunSummary <-> JSON for the per-run record files.
Result<sim::RunSummary> RunSummaryFromJson(const nlohmann::json& j);

}  // namespace recruit::sweep
