// recruit sweep: a grid of closed-loop runs over the controller axes (dT x lambda x estimator x
// seeds) and, from a sweep file, plant axes (any task parameter, plugin config keys of the model)
// on all cores; resumable; one shard of it (--shard K/N) for job arrays, and `recruit sweep merge`
// to join shards into the table an unsharded sweep writes. Writes table.csv/.md, report.md/.html
// with the recommended dT per plant point, sensitivities and figures (docs/sweep.md). The sweep
// itself is src/sweep/sweep.h; this file parses the options, draws through the plot module and
// prints.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <mutex>

#include "cli/command_modules.h"
#include "cli/commands.h"
#include "cli/errors.h"
#include "common/atomic_file.h"
#include "sweep/sweep.h"

namespace recruit::cli {
namespace {

namespace fs = std::filesystem;

struct SweepArgs {
  sweep::SweepDefinition def;
  int threads = 0;
  bool progress = false;
  std::string shard;                // "K/N"
  std::vector<std::string> shards;  // merge: the shards' output folders
};

// The report's drawing through the plot module (cairo), opened on first use.
sweep::Drawing PlotModuleDrawing() {
  auto open = []() -> Result<const PlotModule*> {
    std::string error;
    const PlotModule* plot = OpenPlotModule(&error);
    if (!plot) return IoError(error);
    return plot;
  };
  sweep::Drawing d;
  d.stability_map = [open](const plot::PlotOptions& map) -> Status {
    auto plot = open();
    if (!plot.ok()) return plot.failure();
    std::vector<std::string> written;
    Error failed;
    (*plot)->run(&map, &written, &failed);
    if (!failed.message.empty()) return IoError("stability map: " + failed.message);
    return Status::Ok();
  };
  d.figure = [open](const plot::Figure& fig, int w, int h, plot::Format f) -> Result<std::string> {
    auto plot = open();
    if (!plot.ok()) return plot.failure();
    std::string bytes;
    Error why;
    (*plot)->figure(&fig, w, h, f, &bytes, &why);
    if (!why.message.empty()) return why;
    return bytes;
  };
  return d;
}

// Progress and the remaining time on stderr: in place on a terminal, else (a batch job's log)
// a line at most every 10 s. The estimate uses the runs made now (not those reused).
class ProgressLine {
 public:
  explicit ProgressLine(bool forced) : tty_(::isatty(STDERR_FILENO)), on_(forced || tty_) {}
  void operator()(int done, int total) {
    if (!on_) return;
    std::lock_guard<std::mutex> l(mu_);
    if (first_done_ < 0) first_done_ = done - 1;
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
    const int made = done - first_done_;
    const double eta = el / made * (total - done);
    if (!tty_ && done != total && el - last_line_ < 10) return;
    last_line_ = el;
    std::fprintf(stderr, "%s  %d / %d runs, %.0f s elapsed, ETA %.0f s%s", tty_ ? "\r" : "", done,
                 total, el, eta, tty_ && done != total ? "   " : "\n");
  }

 private:
  const bool tty_, on_;
  std::mutex mu_;
  const std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
  int first_done_ = -1;
  double last_line_ = -1e9;
};

int RunSweepCommand(const SweepArgs& a) {
  const std::string cmd = "sweep";
  auto prep = sweep::Prepare(a.def);
  if (!prep.ok()) return Fail(cmd, prep.failure());
  const sweep::PreparedSweep& p = *prep;
  ProgressLine progress(a.progress);
  sweep::RunHooks hooks;
  hooks.progress = [&progress](int done, int total) { progress(done, total); };
  hooks.starting = [&](int runs) {
    std::cerr << "recruit sweep: " << runs << " runs"
              << (a.shard.empty()
                      ? ""
                      : " (shard " + a.shard + " of " + std::to_string(p.grid.size()) + ")")
              << " into " << a.def.out
              << " (per-run log: " << (fs::path(a.def.out) / "progress.log").string() << ")\n";
  };
  auto outcome = sweep::Run(p, a.def, a.shard, a.threads, hooks, PlotModuleDrawing());
  if (!outcome.ok()) return Fail(cmd, outcome.failure());
  double wall = 0, simulated = 0;
  for (const auto& r : outcome->runs) {
    wall += r.wall_seconds;
    simulated += r.duration;
  }
  if (!a.shard.empty()) {
    std::cout << "recruit sweep: shard " << a.shard << ": " << outcome->executed << " runs made, "
              << outcome->reused << " reused; " << simulated << " s simulated in " << wall
              << " s of run time; join the shards with `recruit sweep merge`\n";
    return exit_code::kOk;
  }
  std::cout << "recruit sweep: " << outcome->executed << " runs made, " << outcome->reused
            << " reused; " << simulated << " s simulated in " << wall
            << " s of run time; wrote table.csv, table.md, report.md, report.html in " << a.def.out
            << "\n";
  auto md = ReadFile((fs::path(a.def.out) / "table.md").string());
  if (md.ok()) {
    const auto pos = md->find("## Shortest");
    if (pos != std::string::npos) std::cout << md->substr(pos);
  }
  return exit_code::kOk;
}

// recruit sweep merge: the shards' run records, checked against the sweep recomputed from the
// same definition, copied into --out and reported exactly as an unsharded sweep.
int RunMergeCommand(const SweepArgs& a) {
  const std::string cmd = "sweep merge";
  auto prep = sweep::Prepare(a.def);
  if (!prep.ok()) return Fail(cmd, prep.failure());
  auto note = [](const std::string& line) { std::cerr << "recruit sweep merge: " << line << "\n"; };
  auto merged = sweep::Merge(*prep, a.def, a.shards, PlotModuleDrawing(), note);
  if (!merged.ok()) return Fail(cmd, merged.failure());
  std::cout << "recruit sweep merge: " << merged->shards << " shards, " << merged->outcome.reused
            << " runs; wrote table.csv, table.md, report.md, report.html in " << a.def.out << "\n";
  return exit_code::kOk;
}

// The options shared by `sweep` and `sweep merge` (the sweep's definition must be the same).
void AddDefinitionOptions(CLI::App* cmd, sweep::SweepDefinition* a) {
  auto track = [a](CLI::Option* o, const std::string& name) {
    o->each([a, name](const std::string&) { a->given.insert(name); });
    return o;
  };
  track(cmd->add_option("--task", a->task, "Task file (JSON, docs/formats/task.md)")
            ->check(CLI::ExistingFile),
        "task");
  cmd->add_option("--sweep", a->sweep_file,
                  "Sweep file (JSON, docs/sweep.md): task, controller and plant axes; options "
                  "given here override its values")
      ->check(CLI::ExistingFile);
  track(cmd->add_option("--dT", a->dTs, "Sampling periods, s, in (0, 1000], comma separated")
            ->delimiter(',')
            ->check(SamplingPeriod())
            ->capture_default_str(),
        "dT");
  track(cmd->add_option("--lambda", a->lambdas, "Law gains in (0, 1], comma separated")
            ->delimiter(',')
            ->check(Fraction())
            ->capture_default_str(),
        "lambda");
  track(cmd->add_option(
               "--estimator", a->estimators,
               "Estimators, comma separated (output, kalman2, kalman-augmented, kalman-failures)")
            ->delimiter(',')
            ->check(CLI::IsMember({"output", "kalman2", "kalman-augmented", "kalman-failures"}))
            ->capture_default_str(),
        "estimator");
  track(cmd->add_option("--seeds", a->seeds, "Seeds per grid cell, 1..100000")
            ->check(CLI::Range(1, 100000))
            ->capture_default_str(),
        "seeds");
  track(cmd->add_option("--base-seed", a->base_seed,
                        "Run seeds are Rng::DeriveSeed(base, seed index)")
            ->capture_default_str(),
        "base-seed");
  cmd->add_option("--duration", a->duration, "Simulated time per run, s [default: task's]")
      ->check(Positive());
  cmd->add_option("--filter-model", a->filter_model,
                  "Filter model file for kalman-augmented [default: the one identified for "
                  "each dT, models/identified/]")
      ->check(CLI::ExistingFile);
  track(cmd->add_option("--max-overshoot", a->criterion.max_overshoot,
                        "Criterion: mean step overshoot at most this fraction (>= 0)")
            ->check(NonNegative())
            ->capture_default_str(),
        "max-overshoot");
  track(cmd->add_option("--min-settled", a->criterion.min_settled,
                        "Criterion: at least this fraction of steps settle in the band, [0, 1]")
            ->check(NumberIn(0, false, 1, "in [0, 1]"))
            ->capture_default_str(),
        "min-settled");
}

}  // namespace

void AddSweepCommand(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<SweepArgs>();
  auto* cmd = app.add_subcommand(
      "sweep",
      "Run a task over controller axes (dT x lambda x estimator x seeds) and plant axes from a "
      "sweep file on all cores (resumable, shardable) and write a table, a report with the "
      "recommended dT per plant point, sensitivities and figures");
  AddDefinitionOptions(cmd, &args->def);
  args->def.identify_missing_models = true;  // a missing filter model is identified, cached
  cmd->add_option("--out", args->def.out, "Output directory (runs/ inside it makes it resumable)")
      ->capture_default_str();
  cmd->add_option("--threads", args->threads, "Worker threads, 0..4096 (0 = all cores)")
      ->check(CLI::Range(0, 4096))
      ->capture_default_str();
  cmd->add_option("--shard", args->shard,
                  "Run only shard K of N (K/N, 1 <= K <= N): runs with grid index % N == K-1; "
                  "join the shards' folders with `recruit sweep merge`");
  cmd->add_flag("--progress", args->progress,
                "Show progress and the remaining time even when stderr is not a terminal");

  auto margs = std::make_shared<SweepArgs>();
  auto* merge = cmd->add_subcommand(
      "merge",
      "Join the output folders of `recruit sweep --shard K/N` runs into the table and report an "
      "unsharded sweep writes (give the same sweep definition: --sweep/--task and options)");
  AddDefinitionOptions(merge, &margs->def);
  margs->def.identify_missing_models = true;
  merge->add_option("--out", margs->def.out, "Output directory of the merged sweep")->required();
  merge->add_option("shards", margs->shards, "The shards' output folders")->required();
  merge->callback([margs, &exit_code] { exit_code = RunMergeCommand(*margs); });
  cmd->callback([args, merge, &exit_code] {
    if (merge->parsed()) return;
    exit_code = RunSweepCommand(*args);
  });
}

}  // namespace recruit::cli
