// A whole sweep as `recruit sweep` runs it: the definition (options over a sweep file) resolved
// into its plant points and grid, the output folder locked and checked to hold this sweep, the
// runs made or reused (all, or one shard), and the tables, report and figures written; and the
// merge of shards into what an unsharded sweep writes (docs/sweep.md). The CLI only parses its
// options into a SweepDefinition and prints; the drawing (cairo) is passed in.
#pragma once

#include <cstdint>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include "common/file_lock.h"
#include "common/result.h"
#include "plot/plot_run.h"
#include "sim/task.h"
#include "sweep/grid.h"
#include "sweep/sweep_file.h"
#include "sweep/sweep_report.h"
#include "sweep/table.h"

namespace recruit::sweep {

// What defines a sweep: a task and the controller axes, optionally a sweep file (plant axes and
// defaults for the rest). A value named in `given` overrides the sweep file's.
struct SweepDefinition {
  std::string task;
  std::string sweep_file;
  std::string out = "sweep";
  std::vector<double> dTs{0.25, 0.5, 1.0, 2.0};
  std::vector<double> lambdas{0.2};
  std::vector<std::string> estimators{"output", "kalman-augmented"};
  int seeds = 20;
  std::uint64_t base_seed = 1;
  double duration = 0;  // > 0: overrides the sweep file's and the task's
  std::string filter_model;
  TrackingCriterion criterion;
  // Set explicitly: "task", "dT", "lambda", "estimator", "seeds", "base-seed", "max-overshoot",
  // "min-settled".
  std::set<std::string> given;
  // A kalman-augmented run whose plant has no cached filter model identifies one (and caches it,
  // identification/model_cache.h); off, such a run fails. `recruit sweep` turns it on.
  bool identify_missing_models = false;
};

// One plant point made concrete: the task (its model possibly a generated variant) and the texts
// its runs' resume key is made of.
struct PlantTask {
  sim::Task task;
  std::string task_text;   // the task document with the point's values (model path as given)
  std::string model_text;  // the model the runs load
};

// The definition resolved into its grid.
struct PreparedSweep {
  SweepFile file;
  std::string task_path;
  sim::Task task;  // the task as given
  SweepSpec spec;
  TrackingCriterion criterion;
  std::vector<PlantTask> plant;
  std::vector<SweepRun> grid;  // each with its input hash
  std::string description;     // one line: what is swept
};

// Reads the sweep file and the task, applies each plant point (an edited model is written under
// `out`/models, named by its content) and expands the grid. Errors: kUsage without a task or
// with a bad grid, kIo for a file that cannot be read or written, else kBadInput.
Result<PreparedSweep> Prepare(const SweepDefinition& d);

// The input hash of a run of `p` (SweepRun::input_hash) at any dT, lambda, estimator and seed,
// as Prepare sets it for the grid's runs: the tune makes runs off the grid.
std::string InputHash(const PreparedSweep& p, const SweepRun& run);

// Checks that no output replaces an input (kUsage), creates `d.out` and takes its lock (kIo).
Result<FileLock> OpenOutput(const PreparedSweep& p, const SweepDefinition& d);

// The drawing the report needs, from src/plot (`recruit` reaches it through its plot module).
struct Drawing {
  FigureRenderer figure;
  std::function<Status(const plot::PlotOptions&)> stability_map;
};

// Writes table.csv/.md, stability.dat and .png (without plant axes), report.md/.html and their
// figures into `out` (failures are kIo).
Status WriteReports(const PreparedSweep& p, const std::vector<sim::RunSummary>& runs,
                    const std::string& out, const Drawing& draw);

struct RunHooks {
  std::function<void(int runs)> starting;             // the runs to make or reuse, once locked
  std::function<void(int done, int total)> progress;  // after each run (serialised)
};

// Runs the sweep, or its shard "K/N" (`shard` non-empty), into `d.out`: locks it, checks that it
// holds no other sweep (sweep.json), makes the runs not yet recorded there, then writes a shard's
// manifest (shard.json) or, unsharded, the reports. The folder's lock is held until it returns.
Result<SweepOutcome> Run(const PreparedSweep& p, const SweepDefinition& d, const std::string& shard,
                         int threads, const RunHooks& hooks, const Drawing& draw);

struct MergeOutcome {
  int shards = 0;
  SweepOutcome outcome;
};

// Joins the finished shards' folders into `d.out` (their run records, checked against the grid
// `p` recomputes) and writes the reports an unsharded sweep writes. `note` gets a line for each
// folder skipped (no shard.json: an unfinished shard).
Result<MergeOutcome> Merge(const PreparedSweep& p, const SweepDefinition& d,
                           const std::vector<std::string>& shard_dirs, const Drawing& draw,
                           const std::function<void(const std::string&)>& note);

}  // namespace recruit::sweep
