// recruit tune: the adaptive search for the window of sampling periods that meets the tracking
// criterion, per plant point, estimator and lambda (src/sweep/tune.h, docs/sweep.md "recruit
// tune"): brackets and bisects dT on a log lattice, adds seeds where a period is uncertain, and
// writes tune.md and tune.json. Resumable: runs are recorded under <out>/runs as a sweep's.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <limits>
#include <mutex>
#include <tuple>

#include "cli/command_modules.h"
#include "cli/commands.h"
#include "cli/errors.h"
#include "sweep/tune.h"

namespace recruit::cli {
namespace {

struct TuneArgs {
  sweep::TuneDefinition def;
  std::vector<double> range{0.0625, 4};
  double max_step_overshoot = -1;  // < 0: no limit on the worst step
  double quantum = -1;             // < 0: the physics timestep
  int threads = 0;
  bool progress = false;
  std::string shard;  // "K/N"
};

// The figure's drawing through the plot module (cairo), opened on first use.
sweep::FigureRenderer PlotModuleFigure() {
  return [](const plot::Figure& fig, int w, int h, plot::Format f) -> Result<std::string> {
    std::string error;
    const PlotModule* plot = OpenPlotModule(&error);
    if (!plot) return IoError(error);
    std::string bytes;
    Error why;
    plot->figure(&fig, w, h, f, &bytes, &why);
    if (!why.message.empty()) return why;
    return bytes;
  };
}

int RunTuneCommand(TuneArgs& a) {
  const std::string cmd = "tune";
  sweep::TuneDefinition& d = a.def;
  if (a.range.size() != 2) return Fail(cmd, "--dT-range needs two values: MIN,MAX", 2);
  d.settings.dT_min = a.range[0];
  d.settings.dT_max = a.range[1];
  if (a.max_step_overshoot >= 0) d.criterion.max_step_overshoot = a.max_step_overshoot;
  if (a.quantum >= 0) d.settings.dT_quantum = a.quantum;
  if (!a.shard.empty()) {
    auto s = sweep::ParseShard(a.shard);
    if (!s.ok()) return Fail(cmd, s.error(), exit_code::kUsage);
    std::tie(d.shard_k, d.shard_n) = *s;
  }
  if (std::string why = sweep::CheckTuneSettings(d.settings); !why.empty()) {
    return Fail(cmd, why, exit_code::kUsage);
  }
  // The sweep's definition carries the task, plant axes and controller axes; its dT grid and seed
  // count are the search's, not the sweep file's.
  d.sweep.dTs = {d.settings.dT_min};
  d.sweep.seeds = 1;
  d.sweep.given.insert({"dT", "seeds"});
  auto prep = sweep::Prepare(d.sweep);
  if (!prep.ok()) return Fail(cmd, prep.failure());
  d.criterion.tracking = prep->criterion;  // options over the sweep file's criterion
  if (a.quantum < 0) d.settings.dT_quantum = sweep::PhysicsTimestep(*prep);
  if (std::string why = sweep::CheckTuneSettings(d.settings); !why.empty()) {
    return Fail(cmd, why, exit_code::kUsage);
  }
  const bool tty = ::isatty(STDERR_FILENO);
  std::mutex mu;
  auto t0 = std::chrono::steady_clock::now();
  double last = -1e9;
  sweep::TuneHooks hooks;
  hooks.round = [&](int round, int runs) {
    std::cerr << (tty ? "\n" : "") << "recruit tune: round " << round << ": " << runs
              << " runs into " << d.sweep.out << "\n";
  };
  hooks.progress = [&](int done, int total) {
    if (!tty && !a.progress) return;
    std::lock_guard<std::mutex> l(mu);
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!tty && done != total && el - last < 10) return;
    last = el;
    std::fprintf(stderr, "%s  %d / %d runs, %.0f s elapsed%s", tty ? "\r" : "", done, total, el,
                 tty ? "   " : "\n");
  };
  auto out = sweep::Tune(*prep, d, a.threads, hooks);
  if (!out.ok()) return Fail(cmd, out.failure());
  if (Status s = sweep::WriteTuneReport(*prep, d, *out, PlotModuleFigure()); !s.ok()) {
    return Fail(cmd, s.failure());
  }
  if (tty) std::cerr << "\n";
  std::cout << "recruit tune: " << out->runs << " runs (" << out->executed << " made, "
            << out->reused << " reused) in " << out->rounds << " rounds; the lattice grid would "
            << "need " << out->grid_runs
            << (out->check_runs ? "; " + std::to_string(out->check_runs) + " on new seeds"
                                : std::string())
            << "; wrote tune.md, tune.json in " << d.sweep.out << "\n";
  const std::string md = sweep::TuneMarkdown(*prep, d, *out);
  // The windows and, when checked, the recommendations on new seeds.
  const auto a0 = md.find("## Windows");
  auto a1 = md.find("\n## ", a0 + 1);
  const std::string checked = "\n## The recommendation on new seeds";
  if (a1 != std::string::npos && md.compare(a1, checked.size(), checked) == 0) {
    a1 = md.find("\n## ", a1 + 1);
  }
  if (a0 != std::string::npos) std::cout << md.substr(a0, a1 - a0) << "\n";
  return exit_code::kOk;
}

}  // namespace

void AddTuneCommand(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<TuneArgs>();
  sweep::SweepDefinition& def = args->def.sweep;
  def.identify_missing_models = true;
  def.out = "tune";
  def.estimators = {"kalman-augmented"};
  sweep::TuneSettings& s = args->def.settings;
  auto* cmd = app.add_subcommand(
      "tune",
      "Find the window of sampling periods dT that meets the tracking criterion (adaptive: "
      "brackets and bisects log dT, adds seeds where uncertain), per plant point, estimator and "
      "lambda; report its edges, a recommended dT inside it and why each dT tried fails");
  auto track = [&def](CLI::Option* o, const std::string& name) {
    o->each([&def, name](const std::string&) { def.given.insert(name); });
    return o;
  };
  track(cmd->add_option("--task", def.task, "Task file (JSON, docs/formats/task.md)")
            ->check(CLI::ExistingFile),
        "task");
  cmd->add_option("--sweep", def.sweep_file,
                  "Sweep file (docs/sweep.md): task, plant axes, lambda, estimator, criterion; "
                  "its dT and seeds are not used")
      ->check(CLI::ExistingFile);
  track(cmd->add_option("--lambda", def.lambdas, "Law gains in (0, 1], comma separated")
            ->delimiter(',')
            ->check(Fraction())
            ->capture_default_str(),
        "lambda");
  track(cmd->add_option("--estimator", def.estimators,
                        "Estimators, comma separated (output, kalman2, kalman-augmented)")
            ->delimiter(',')
            ->check(CLI::IsMember({"output", "kalman2", "kalman-augmented"}))
            ->capture_default_str(),
        "estimator");
  track(cmd->add_option("--base-seed", def.base_seed,
                        "Run seeds are Rng::DeriveSeed(base, seed index)")
            ->capture_default_str(),
        "base-seed");
  cmd->add_option("--duration", def.duration, "Simulated time per run, s [default: task's]")
      ->check(Positive());
  cmd->add_option("--filter-model", def.filter_model,
                  "Filter model file for kalman-augmented [default: identified per dT]")
      ->check(CLI::ExistingFile);
  track(cmd->add_option("--max-overshoot", def.criterion.max_overshoot,
                        "Criterion per seed: its mean step overshoot at most this fraction")
            ->check(NonNegative())
            ->capture_default_str(),
        "max-overshoot");
  track(cmd->add_option("--min-settled", def.criterion.min_settled,
                        "Criterion per seed: at least this fraction of its steps settle, [0, 1]")
            ->check(NumberIn(0, false, 1, "in [0, 1]"))
            ->capture_default_str(),
        "min-settled");
  cmd->add_option("--max-step-overshoot", args->max_step_overshoot,
                  "Criterion per seed: its worst step's overshoot at most this fraction "
                  "[default: no limit]")
      ->check(NonNegative());
  cmd->add_option("--dT-range", args->range, "Periods searched, s: MIN,MAX (log lattice)")
      ->delimiter(',')
      ->expected(2)
      ->check(SamplingPeriod())
      ->capture_default_str();
  cmd->add_option("--dT-quantum", args->quantum,
                  "Periods tried are whole multiples of this, s (0: any) [default: the physics "
                  "timestep; kalman-augmented identifies models only for its multiples]")
      ->check(NonNegative());
  cmd->add_option("--tolerance", s.tolerance, "Edges known to a factor 1 + this, [0.01, 1]")
      ->capture_default_str();
  cmd->add_option("--level", s.level,
                  "Fraction of seeds that must meet the criterion at a dT, (0, 1)")
      ->capture_default_str();
  cmd->add_option("--confidence", s.confidence, "Of the Wilson interval on that fraction")
      ->capture_default_str();
  cmd->add_option("--seeds", s.initial_seeds, "Seeds of a new dT (doubled while undecided)")
      ->capture_default_str();
  cmd->add_option("--max-seeds", s.max_seeds, "Seeds at most per dT")->capture_default_str();
  cmd->add_option("--initial-points", s.initial_points, "dT spread over the range to start from")
      ->capture_default_str();
  cmd->add_option("--check-seeds", args->def.check_seeds,
                  "After the search, run each recommended dT on this many seeds it never used "
                  "and say whether its claim holds (0: no check)")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str();
  cmd->add_option("--check-base-seed", args->def.check_base_seed,
                  "Base seed of those new seeds (must differ from --base-seed)")
      ->capture_default_str();
  cmd->add_option("--out", def.out, "Output directory (runs/ inside it makes it resumable)")
      ->capture_default_str();
  cmd->add_option("--threads", args->threads, "Worker threads, 0..4096 (0 = all cores)")
      ->check(CLI::Range(0, 4096))
      ->capture_default_str();
  cmd->add_option("--shard", args->shard,
                  "Run only shard K of N (K/N): the searches (plant point x lambda x estimator) "
                  "with index % N == K-1; copy the shards' runs/ into one folder and tune there "
                  "to report them all (every run reused)");
  cmd->add_flag("--progress", args->progress, "Show progress even when stderr is not a terminal");
  cmd->callback([args, &exit_code] { exit_code = RunTuneCommand(*args); });
}

}  // namespace recruit::cli
