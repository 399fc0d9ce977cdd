// recruit simulate --task FILE: one closed-loop run; writes the per-step CSV and the JSON summary.
#include <unistd.h>

#include <filesystem>
#include <iostream>

#include "cli/commands.h"
#include "cli/errors.h"
#include "cli/run_options.h"
#include "common/atomic_file.h"
#include "common/output_path.h"
#include "sim/csv_writer.h"
#include "sim/run_task.h"

namespace recruit::cli {
namespace {

struct SimulateArgs {
  std::string task;
  std::string out = ".";
  std::string csv, summary;
  int csv_every = 1;
  sim::RunOptions run;
};

int RunSimulate(const SimulateArgs& a) {
  const std::string cmd = "simulate";
  auto task = sim::Task::FromFile(a.task);
  if (!task.ok()) return Fail(cmd, task.failure());
  // The task's name becomes part of the default output names: it must stay inside --out.
  if (a.csv.empty() || a.summary.empty()) {
    if (Status s = CheckFileNameComponent(task->name, a.task + ": name"); !s.ok()) {
      return Fail(cmd, s.error(), exit_code::kBadInput);
    }
  }
  const std::filesystem::path out(a.out);
  const std::string csv = a.csv.empty() ? (out / (task->name + "_steps.csv")).string() : a.csv;
  const std::string summary =
      a.summary.empty() ? (out / (task->name + "_summary.json")).string() : a.summary;
  const sim::ControllerSettings settings = sim::EffectiveSettings(*task, a.run);
  const std::vector<std::pair<std::string, std::string>> inputs = {
      {"--task", a.task},
      {"the task's model", task->model_path},
      {"the filter model", settings.filter_model}};
  for (const auto& [label, path] : {std::pair{"--csv", csv}, std::pair{"--summary", summary}}) {
    if (Status s = CheckNotAnInput(path, label, inputs); !s.ok()) {
      return Fail(cmd, s.error(), exit_code::kUsage);
    }
  }
  if (csv == summary) return Fail(cmd, "--csv and --summary are the same file", exit_code::kUsage);
  std::error_code ec;
  std::filesystem::create_directories(a.out, ec);
  if (ec)
    return Fail(cmd, "cannot create --out '" + ShortText(a.out) + "': " + ec.message(),
                exit_code::kIo);
  sim::RunOptions run = a.run;
  run.progress = run.progress || ::isatty(STDERR_FILENO);
  // The summary's temporary file is opened before the run, so an unwritable --summary fails
  // at once and nothing is written.
  AtomicFile summary_file(summary, std::ios::binary);
  if (!summary_file.ok()) return Fail(cmd, summary_file.error(), exit_code::kIo);
  sim::CsvStepWriter writer(csv, a.csv_every);
  auto result = sim::RunTask(*task, run, {&writer});
  if (!result.ok()) return Fail(cmd, result.failure());
  summary_file.stream() << result->ToJson().dump(2) << "\n";
  // Both or neither: the summary first (a failure leaves the CSV's temporary file, removed with
  // the writer), then the CSV (a failure removes the summary just written).
  if (Status s = summary_file.Commit(); !s.ok()) return Fail(cmd, s.error(), exit_code::kIo);
  if (Status s = writer.Commit(); !s.ok()) {
    std::error_code ec;
    std::filesystem::remove(summary, ec);
    return Fail(cmd, s.error(), exit_code::kIo);
  }
  const auto& m = result->metrics;
  std::cout << "task " << result->task << ", estimator " << result->estimator << ", dT "
            << result->dT << " s, lambda " << result->lambda << ", seed " << result->seed
            << "\n  tracking RMSE " << m.tracking_rmse << " " << result->unit << ", IAE " << m.iae
            << ", overshoot " << 100 * m.overshoot << " % (max " << 100 * m.max_overshoot
            << " %), settling " << m.settling_time << " s, oscillation " << m.oscillation
            << "\n  switching " << m.switching_rate << " /unit/s, estimator RMSE "
            << m.estimator_rmse << " units, mean NEES " << m.mean_nees << "\n  " << result->duration
            << " s simulated in " << result->wall_seconds << " s ("
            << result->duration / result->wall_seconds << "x real time"
            << (result->identification_seconds > 0
                    ? ", after " + std::to_string(result->identification_seconds) +
                          " s identifying filter models"
                    : std::string())
            << ")\n  wrote " << csv << " and " << summary << "\n";
  return exit_code::kOk;
}

}  // namespace

void AddSimulateCommand(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<SimulateArgs>();
  auto* cmd = app.add_subcommand(
      "simulate",
      "Run one task in closed loop (plant, estimator, broadcast controller) and write a per-step "
      "CSV and a JSON summary of its metrics");
  cmd->add_option("--task", args->task, "Task file (JSON, docs/formats/task.md)")
      ->required()
      ->check(CLI::ExistingFile);
  AddRunOptions(cmd, &args->run);
  cmd->add_option("--out", args->out, "Directory for the outputs")->capture_default_str();
  cmd->add_option("--csv", args->csv, "Per-step CSV [default: OUT/<task name>_steps.csv]");
  cmd->add_option("--summary", args->summary,
                  "JSON summary [default: OUT/<task name>_summary.json]");
  cmd->add_option("--csv-every", args->csv_every,
                  "Write every N-th physics step to the CSV (control instants always)")
      ->check(CLI::Range(1, 1000000000))
      ->capture_default_str();
  cmd->callback([args, &exit_code] { exit_code = RunSimulate(*args); });
}

}  // namespace recruit::cli
