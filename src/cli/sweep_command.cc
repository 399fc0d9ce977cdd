// recruit sweep --task FILE: a grid of closed-loop runs over dT x lambda x estimator x seeds on
// all cores; resumable; writes table.csv, table.md, stability.png and the shortest dT per
// estimator that meets the tracking criterion.
#include <unistd.h>

#include <filesystem>
#include <iostream>
#include <mutex>

#include "cli/commands.h"
#include "common/atomic_file.h"
#include "sim/sweep.h"

namespace recruit::cli {

void AddSweepCommand(CLI::App& app, int& exit_code) {
  struct Args {
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
  auto args = std::make_shared<Args>();
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
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--lambda", args->lambdas, "Law gains in (0, 1], comma separated")
      ->delimiter(',')
      ->check(CLI::Range(1e-9, 1.0))
      ->capture_default_str();
  cmd->add_option("--estimator", args->estimators,
                  "Estimators, comma separated (output, kalman2, kalman-augmented)")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--seeds", args->seeds, "Seeds per grid cell")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--base-seed", args->base_seed, "Run seeds are Rng::DeriveSeed(base, seed index)")
      ->capture_default_str();
  cmd->add_option("--threads", args->threads, "Worker threads (0 = all cores)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--duration", args->duration, "Simulated time per run, s [default: task's]")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--filter-model", args->filter_model,
                  "Filter model file for kalman-augmented [default: the one identified for "
                  "each dT, models/identified/]");
  cmd->add_option("--max-overshoot", args->criterion.max_overshoot,
                  "Criterion: mean step overshoot at most this fraction")
      ->capture_default_str();
  cmd->add_option("--min-settled", args->criterion.min_settled,
                  "Criterion: at least this fraction of steps settle in the 10 % band")
      ->capture_default_str();
  cmd->add_flag("--progress", args->progress, "Show progress even when stderr is not a terminal");
  cmd->callback([args, &exit_code] {
    auto fail = [&exit_code](const std::string& msg) {
      std::cerr << "recruit sweep: " << msg << "\n";
      exit_code = 1;
    };
    auto task = sim::Task::FromFile(args->task);
    if (!task.ok()) return fail(task.error());
    sim::SweepSpec spec;
    spec.dTs = args->dTs;
    spec.lambdas = args->lambdas;
    spec.estimators = args->estimators;
    spec.seeds = args->seeds;
    spec.base_seed = args->base_seed;
    if (args->duration > 0) spec.duration = args->duration;
    if (!args->filter_model.empty()) spec.filter_model = args->filter_model;
    auto grid = sim::ExpandGrid(spec);
    if (!grid.ok()) return fail(grid.error());

    // A directory holds one sweep: the task and duration must match to resume.
    std::error_code ec;
    std::filesystem::create_directories(args->out, ec);
    if (ec) return fail("--out '" + args->out + "': " + ec.message());
    const std::string id_path = (std::filesystem::path(args->out) / "sweep.json").string();
    nlohmann::json id = {
        {"task", std::filesystem::absolute(args->task).lexically_normal().string()},
        {"duration", spec.duration ? *spec.duration : task->duration},
        {"filter_model", args->filter_model}};
    if (std::filesystem::exists(id_path)) {
      auto text = ReadFile(id_path);
      auto old = nlohmann::json::parse(text.ok() ? *text : "", nullptr, false);
      if (old.is_discarded() || old != id) {
        return fail("'" + args->out + "' holds a sweep of another task or duration (" + id_path +
                    "); use another --out");
      }
    } else if (Status s = WriteFileAtomically(id_path, id.dump(2) + "\n"); !s.ok()) {
      return fail(s.error());
    }

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
    const bool progress = args->progress || ::isatty(STDERR_FILENO);
    std::mutex mu;
    auto report = [&](int done, int total) {
      if (!progress) return;
      std::lock_guard<std::mutex> l(mu);
      std::fprintf(stderr, "\r  %d / %d runs", done, total);
      if (done == total) std::fprintf(stderr, "\n");
    };
    std::cerr << "recruit sweep: " << grid->size() << " runs into " << args->out << "\n";
    auto outcome = sim::RunSweep(*grid, args->out, run, args->threads, report);
    if (!outcome.ok()) {
      return fail(outcome.error() + " (finished runs are kept; run again to resume)");
    }
    const auto cells = sim::Aggregate(outcome->runs, args->criterion);
    if (Status s = sim::WriteSweepReport(cells, args->criterion, args->out, task->name); !s.ok()) {
      return fail(s.error());
    }
    double wall = 0, simulated = 0;
    for (const auto& r : outcome->runs) {
      wall += r.wall_seconds;
      simulated += r.duration;
    }
    std::cout << "recruit sweep: " << outcome->executed << " runs made, " << outcome->reused
              << " reused; " << simulated << " s simulated in " << wall
              << " s of run time; wrote table.csv, table.md, stability.png in " << args->out
              << "\n";
    auto md = ReadFile((std::filesystem::path(args->out) / "table.md").string());
    if (md.ok()) {
      const auto pos = md->find("## Shortest");
      if (pos != std::string::npos) std::cout << md->substr(pos);
    }
  });
}

}  // namespace recruit::cli
