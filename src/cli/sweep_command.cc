// recruit sweep --task FILE: a grid of closed-loop runs over dT x lambda x estimator x seeds on
// all cores; resumable; writes table.csv, table.md, stability.png and the shortest dT per
// estimator that meets the tracking criterion.
#include <fmt/format.h>
#include <unistd.h>

#include <filesystem>
#include <iostream>
#include <map>
#include <mutex>

#include "cli/commands.h"
#include "cli/errors.h"
#include "common/atomic_file.h"
#include "common/content_hash.h"
#include "common/file_lock.h"
#include "common/json_file.h"
#include "common/output_path.h"
#include "control/on_count_estimator.h"
#include "sim/sweep.h"

namespace recruit::cli {
namespace {

struct SweepArgs {
  std::string task;
  std::string out = "sweep";
  std::vector<double> dTs{0.25, 0.5, 1.0, 2.0};
  std::vector<double> lambdas{0.2};
  std::vector<std::string> estimators{"output", "kalman-augmented"};
  int seeds = 20;
  std::uint64_t base_seed = 1;
  int threads = 0;
  double duration = 0;
  std::string filter_model;
  sim::TrackingCriterion criterion;
  bool progress = false;
};

// Content of a file for the resume key ("" plus a marker when it cannot be read: the run itself
// will then fail and report it).
std::string ContentOf(const std::string& path) {
  if (path.empty()) return "<none>";
  auto text = ReadFile(path);
  return text.ok() ? *text : "<unreadable " + path + ">";
}

// The resume key of one run: a hash of everything that determines its result (the task file's
// content, the model file's content, the filter model file's content, the run's options and
// the code version), so an edited input or a new build is never served an old result.
std::string RunInputHash(const sim::Task& task, const std::string& task_text,
                         const sim::SweepSpec& spec, const sim::SweepRun& g,
                         std::map<std::string, std::string>& cache) {
  sim::RunOptions o;
  o.estimator = g.estimator;
  o.dT = g.dT;
  o.lambda = g.lambda;
  o.filter_model = spec.filter_model;
  const sim::ControllerSettings c = sim::EffectiveSettings(task, o);
  std::string filter_model = c.filter_model;
  if (filter_model.empty() && c.estimator == "kalman-augmented") {
    filter_model = control::DefaultModelFile(c.dT, 20);
  }
  auto content = [&cache](const std::string& path) -> const std::string& {
    auto it = cache.find(path);
    if (it == cache.end()) it = cache.emplace(path, ContentOf(path)).first;
    return it->second;
  };
  ContentHash h;
  h.Add(CodeVersion()).Add(task_text).Add(content(task.model_path)).Add(content(filter_model));
  h.Add(c.estimator).Add(fmt::format("{:.17g} {:.17g} {:.17g}", c.dT, c.lambda, c.force_noise_std));
  h.Add(fmt::format("{:.17g} {}", spec.duration ? *spec.duration : task.duration, g.seed));
  return h.Hex();
}

int RunSweepCommand(const SweepArgs& a) {
  const std::string cmd = "sweep";
  auto task_text = ReadFile(a.task);
  if (!task_text.ok()) return Fail(cmd, task_text.error(), exit_code::kIo);
  auto task = sim::Task::FromFile(a.task);
  if (!task.ok()) return Fail(cmd, task.error());
  sim::SweepSpec spec;
  spec.dTs = a.dTs;
  spec.lambdas = a.lambdas;
  spec.estimators = a.estimators;
  spec.seeds = a.seeds;
  spec.base_seed = a.base_seed;
  if (a.duration > 0) spec.duration = a.duration;
  if (!a.filter_model.empty()) spec.filter_model = a.filter_model;
  auto grid = sim::ExpandGrid(spec);
  if (!grid.ok()) return Fail(cmd, grid.error(), exit_code::kUsage);

  // The outputs must not replace the inputs (a task file kept in the output folder).
  const std::filesystem::path out(a.out);
  for (const char* name : {"sweep.json", "table.csv", "table.md", "stability.dat", "stability.gp",
                           "stability.png", "sweep.lock"}) {
    Status s = CheckNotAnInput((out / name).string(), "output",
                               {{"--task", a.task},
                                {"--filter-model", a.filter_model},
                                {"the task's model", task->model_path}});
    if (!s.ok()) return Fail(cmd, s.error(), exit_code::kUsage);
  }
  std::error_code ec;
  std::filesystem::create_directories(a.out, ec);
  if (ec)
    return Fail(cmd, "cannot create --out '" + ShortText(a.out) + "': " + ec.message(),
                exit_code::kIo);
  // One sweep per folder at a time: the lock is held until the process ends.
  auto lock = FileLock::TryLock((out / "sweep.lock").string());
  if (!lock.ok()) return Fail(cmd, lock.error(), exit_code::kIo);

  // A directory holds one sweep: the task and duration must match to resume. Which runs can be
  // reused is decided per run by its input hash (an edited task reruns everything).
  const std::string id_path = (out / "sweep.json").string();
  nlohmann::json id = {{"task", std::filesystem::absolute(a.task).lexically_normal().string()},
                       {"duration", spec.duration ? *spec.duration : task->duration},
                       {"filter_model", a.filter_model}};
  if (std::filesystem::exists(id_path)) {
    auto old = LoadJsonFile(id_path);
    if (!old.ok()) return Fail(cmd, old.error());
    if (*old != id) {
      return Fail(cmd,
                  "'" + ShortText(a.out) + "' holds a sweep of another task or duration (" +
                      id_path + "); use another --out",
                  exit_code::kUsage);
    }
  } else if (Status s = WriteFileAtomically(id_path, id.dump(2) + "\n"); !s.ok()) {
    return Fail(cmd, s.error(), exit_code::kIo);
  }
  std::map<std::string, std::string> contents;
  for (auto& g : *grid) g.input_hash = RunInputHash(*task, *task_text, spec, g, contents);

  const sim::Task& t = *task;
  auto run = [&t, &spec](const sim::SweepRun& g) {
    sim::RunOptions o;
    o.estimator = g.estimator;
    o.dT = g.dT;
    o.lambda = g.lambda;
    o.seed = g.seed;
    o.duration = spec.duration;
    o.filter_model = spec.filter_model;
    return sim::RunTask(t, o);
  };
  const bool progress = a.progress || ::isatty(STDERR_FILENO);
  std::mutex mu;
  auto report = [&](int done, int total) {
    if (!progress) return;
    std::lock_guard<std::mutex> l(mu);
    std::fprintf(stderr, "\r  %d / %d runs", done, total);
    if (done == total) std::fprintf(stderr, "\n");
  };
  std::cerr << "recruit sweep: " << grid->size() << " runs into " << a.out << "\n";
  auto outcome = sim::RunSweep(*grid, a.out, run, a.threads, report);
  if (!outcome.ok()) {
    return Fail(cmd, outcome.error() + " (finished runs are kept; run again to resume)");
  }
  const auto cells = sim::Aggregate(outcome->runs, a.criterion);
  if (Status s = sim::WriteSweepReport(cells, a.criterion, a.out, task->name); !s.ok()) {
    return Fail(cmd, s.error(), exit_code::kIo);
  }
  double wall = 0, simulated = 0;
  for (const auto& r : outcome->runs) {
    wall += r.wall_seconds;
    simulated += r.duration;
  }
  std::cout << "recruit sweep: " << outcome->executed << " runs made, " << outcome->reused
            << " reused; " << simulated << " s simulated in " << wall
            << " s of run time; wrote table.csv, table.md, stability.png in " << a.out << "\n";
  auto md = ReadFile((out / "table.md").string());
  if (md.ok()) {
    const auto pos = md->find("## Shortest");
    if (pos != std::string::npos) std::cout << md->substr(pos);
  }
  return exit_code::kOk;
}

}  // namespace

void AddSweepCommand(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<SweepArgs>();
  auto* cmd = app.add_subcommand(
      "sweep",
      "Run a task over a grid of dT x lambda x estimator x seeds on all cores (resumable) and "
      "write a table, a stability map and the shortest dT that meets the tracking criterion");
  cmd->add_option("--task", args->task, "Task file (JSON, docs/formats/task.md)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", args->out, "Output directory (runs/ inside it makes it resumable)")
      ->capture_default_str();
  cmd->add_option("--dT", args->dTs, "Sampling periods, s, comma separated")
      ->delimiter(',')
      ->check(Positive())
      ->capture_default_str();
  cmd->add_option("--lambda", args->lambdas, "Law gains in (0, 1], comma separated")
      ->delimiter(',')
      ->check(Fraction())
      ->capture_default_str();
  cmd->add_option("--estimator", args->estimators,
                  "Estimators, comma separated (output, kalman2, kalman-augmented)")
      ->delimiter(',')
      ->check(CLI::IsMember({"output", "kalman2", "kalman-augmented"}))
      ->capture_default_str();
  cmd->add_option("--seeds", args->seeds, "Seeds per grid cell, 1..100000")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--base-seed", args->base_seed, "Run seeds are Rng::DeriveSeed(base, seed index)")
      ->capture_default_str();
  cmd->add_option("--threads", args->threads, "Worker threads, 0..4096 (0 = all cores)")
      ->check(CLI::Range(0, 4096))
      ->capture_default_str();
  cmd->add_option("--duration", args->duration, "Simulated time per run, s [default: task's]")
      ->check(Positive());
  cmd->add_option("--filter-model", args->filter_model,
                  "Filter model file for kalman-augmented [default: the one identified for "
                  "each dT, models/identified/]")
      ->check(CLI::ExistingFile);
  cmd->add_option("--max-overshoot", args->criterion.max_overshoot,
                  "Criterion: mean step overshoot at most this fraction (>= 0)")
      ->check(NonNegative())
      ->capture_default_str();
  cmd->add_option("--min-settled", args->criterion.min_settled,
                  "Criterion: at least this fraction of steps settle in the 10 % band, [0, 1]")
      ->check(NumberIn(0, false, 1, "in [0, 1]"))
      ->capture_default_str();
  cmd->add_flag("--progress", args->progress, "Show progress even when stderr is not a terminal");
  cmd->callback([args, &exit_code] { exit_code = RunSweepCommand(*args); });
}

}  // namespace recruit::cli
