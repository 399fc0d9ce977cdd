// recruit tune: the adaptive search for the window of sampling periods dT that meets the tracking
// criterion (tune_search.h decides; this runs it), per plant point, estimator and lambda. Each
// round runs the batch the search asks for with the sweep's runner (threads, one record per run
// under <out>/runs keyed and hashed as a sweep's, so a stopped search started again reuses every
// run it made) and judges each run on its own: its mean step overshoot, its settled fraction, its
// worst step (optional limit) and the datasheet limits of its wires. Writes tune.json, tune.md and
// window.png/.svg. A shard (TuneDefinition::shard_k/n) runs every n-th search.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "common/result.h"
#include "sim/run_task.h"
#include "sweep/sweep.h"
#include "sweep/tune_search.h"

namespace recruit::sweep {

// The criterion one run (one seed) must meet.
struct TuneCriterion {
  TrackingCriterion tracking;  // its mean step overshoot and settled fraction
  double max_step_overshoot = std::numeric_limits<double>::infinity();  // its worst step
};

// Which parts of the criterion one run breaks (several may).
struct SeedCheck {
  bool overshoot = false, settling = false, worst_step = false, limits = false;
  bool meets() const { return !overshoot && !settling && !worst_step && !limits; }
};
SeedCheck CheckSeed(const sim::RunSummary& run, const TuneCriterion& c);

// One period tried, over its seeds.
struct DtRow {
  double dT = 0;
  int seeds = 0, meeting = 0;
  Interval fraction;  // Wilson interval of the fraction of seeds meeting
  Verdict verdict = Verdict::kOpen;
  // Seeds breaking each part of the criterion.
  int fail_overshoot = 0, fail_settling = 0, fail_worst_step = 0, fail_limits = 0;
  // Step overshoot over every step of every seed: mean, 95th percentile, worst.
  double overshoot_mean = 0, overshoot_p95 = 0, overshoot_worst = 0;
  double settled_mean = 0;  // settled fraction, mean over seeds
  // Datasheet limits: the largest peak / limit over runs and bundles (> 1: exceeded).
  double worst_temperature_ratio = 0, worst_stress_ratio = 0;
  // The estimator against the true count (the filter model's quality at this dT).
  double estimator_rmse = 0, mean_nees = 0;
  // The runs' other warnings (e.g. an identified model explaining too little of held-out force,
  // sim/run_task.h), each with the number of runs that gave it; limit excesses are counted above.
  std::vector<std::pair<std::string, int>> warnings;
};

// The search's result for one plant point, estimator and lambda.
struct TuneColumn {
  int plant = 0;
  std::vector<std::pair<std::string, double>> plant_values;
  std::string estimator;
  double lambda = 0;
  Window window;
  double lower_edge = 0, upper_edge = 0;  // s (EdgeEstimate); NaN without a window
  double recommended = 0;                 // s; NaN without a window
  std::vector<DtRow> rows;                // by dT
  // The recommended dT run on seeds the search never used (TuneDefinition::check_seeds; seeds == 0
  // when not checked), and P(X <= meeting) for X ~ Binomial(seeds, level): the claim "at least
  // `level` of seeds meet" is refuted at 5 % when it is below 0.05.
  DtRow check;
  double check_p = 0;
  int runs = 0;
  int max_seeds_used = 0;
};

struct TuneDefinition {
  SweepDefinition sweep;  // task or sweep file, lambdas, estimators, seeds' base, duration, out
  TuneSettings settings;
  TuneCriterion criterion;  // its tracking part replaces sweep.criterion
  // Shard k of n (1 <= k <= n): only the searches (plant point x lambda x estimator, in that
  // order) whose index i has i % n == k - 1. The shards' runs/ copied into one folder and the
  // tune run there unsharded reuse them all and report every search.
  int shard_k = 1, shard_n = 1;
  // After the search, run each recommended dT on this many new seeds, DeriveSeed(check_base_seed,
  // 0..n-1) (a base seed other than the search's), recorded under <out>/check/runs.
  int check_seeds = 0;
  std::uint64_t check_base_seed = 777;
};

struct TuneOutcome {
  std::vector<TuneColumn> columns;
  int executed = 0, reused = 0, rounds = 0;
  int runs = 0;              // made or reused
  int check_runs = 0;        // the recommended dTs on new seeds (made or reused), apart
  long grid_runs = 0;        // the lattice grid with the most seeds any period needed, per column
  double shortest_hold = 0;  // s: the shortest step hold of the task's reference
};

struct TuneHooks {
  std::function<void(int round, int runs)> round;     // before each round's batch
  std::function<void(int done, int total)> progress;  // after each run (serialised)
};

// The physics timestep of the task's runs (the task's override, else its model's; 0 when the
// model does not load): the tune's default dT quantum.
double PhysicsTimestep(const PreparedSweep& p);

// Runs the search into `d.sweep.out` (locked while it runs). `p` from Prepare(d.sweep).
Result<TuneOutcome> Tune(const PreparedSweep& p, const TuneDefinition& d, int threads,
                         const TuneHooks& hooks);

// One period's row from its runs (seed indices 0..n-1), each judged by CheckSeed.
DtRow SummarizeDt(double dT, const std::vector<sim::RunSummary>& runs, const TuneCriterion& c,
                  const TuneSettings& s);

// For a sweep's report: per cell (plant point, estimator, lambda, dT, in grid order) its seeds
// judged one by one (CheckSeed): seeds meeting with the 95 % Wilson interval, why the others
// fail (each part of the criterion, on how many seeds), the step overshoot's mean, 95th
// percentile and worst step, and the runs past a datasheet limit. runs[i] was made for grid[i].
std::string SeedReasonsMarkdown(const std::vector<SweepRun>& grid,
                                const std::vector<sim::RunSummary>& runs,
                                const TrackingCriterion& criterion);

// tune.json (everything, machine-readable) and tune.md (the report) into `d.sweep.out`; with a
// renderer also window.png/.svg (per search the fraction of seeds meeting against log dT with its
// Wilson band, the level, the edges, a censored one dotted with an arrowhead out of the range, and
// the recommended dT), linked from tune.md.
Status WriteTuneReport(const PreparedSweep& p, const TuneDefinition& d, const TuneOutcome& o,
                       const FigureRenderer& render = {});
std::string TuneMarkdown(const PreparedSweep& p, const TuneDefinition& d, const TuneOutcome& o);
nlohmann::json TuneJson(const TuneDefinition& d, const TuneOutcome& o);

}  // namespace recruit::sweep
