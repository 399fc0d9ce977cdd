// recruit replay --log BENCH.csv --task T: drives the task's simulated plant with the log's
// recorded broadcasts and compares its force and angles with the recorded ones (docs/replay.md).
#include <filesystem>
#include <iostream>
#include <string>

#include "cli/command_modules.h"
#include "cli/commands.h"
#include "cli/errors.h"
#include "common/atomic_file.h"
#include "common/output_path.h"
#include "estimation/bench_log.h"
#include "replay/report.h"
#include "sim/task.h"

namespace recruit::cli {
namespace {

struct ReplayArgs {
  std::string log, task, out = ".", prefix;
  replay::ReplayOptions options;
};

int RunReplayCommand(const ReplayArgs& a) {
  namespace fs = std::filesystem;
  const std::string cmd = "replay";
  const std::string prefix = a.prefix.empty() ? fs::path(a.log).stem().string() : a.prefix;
  if (Status s =
          CheckFileNameComponent(prefix, a.prefix.empty() ? "--log's file name" : "--prefix");
      !s.ok()) {
    return Fail(cmd, s.error() + " (name the outputs with --prefix)", exit_code::kUsage);
  }
  auto task = sim::Task::FromFile(a.task);
  if (!task.ok()) return Fail(cmd, task.failure());
  const fs::path out(a.out);
  const std::string json = (out / (prefix + "_replay.json")).string();
  const std::string csv = (out / (prefix + "_replay.csv")).string();
  const std::string png = (out / (prefix + "_replay.png")).string();
  for (const std::string& path : {json, csv, png}) {
    Status s = CheckNotAnInput(
        path, "output",
        {{"--log", a.log}, {"--task", a.task}, {"the task's model", task->model_path}});
    if (!s.ok()) return Fail(cmd, s.error(), exit_code::kUsage);
  }
  auto log = estimation::ReadBenchLog(a.log);
  if (!log.ok()) return Fail(cmd, log.failure());
  auto result = replay::RunReplay(*task, *log, a.options);
  if (!result.ok()) return Fail(cmd, result.failure());
  // Every output is made before any is written: an error leaves nothing behind.
  std::string error;
  const PlotModule* plot = OpenPlotModule(&error);
  if (!plot) return Fail(cmd, error, exit_code::kIo);
  const plot::Figure fig = replay::ReplayFigure(*result);
  std::string bytes;
  Error failed;
  plot->figure(&fig, 1000, 260 + 220 * static_cast<int>(fig.panels.size()), plot::Format::kPng,
               &bytes, &failed);
  if (!failed.message.empty()) {
    return Fail(cmd, "figure: " + failed.message, exit_code::kInternal);
  }
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec) return Fail(cmd, "cannot create --out '" + ShortText(a.out) + "': " + ec.message(), 4);
  AtomicFile files[] = {AtomicFile(json, std::ios::binary), AtomicFile(csv, std::ios::binary),
                        AtomicFile(png, std::ios::binary)};
  for (AtomicFile& f : files) {
    if (!f.ok()) return Fail(cmd, f.error(), exit_code::kIo);
  }
  files[0].stream() << replay::ReportJson(*result).dump(2) << "\n";
  files[1].stream() << replay::SignalsCsv(*result);
  files[2].stream() << bytes;
  for (AtomicFile& f : files) {
    if (Status s = f.Commit(); !s.ok()) {
      for (const std::string& p : {json, csv, png}) fs::remove(p, ec);
      return Fail(cmd, s.error(), exit_code::kIo);
    }
  }
  std::cout << "replayed " << a.log << " (" << log->size() << " control instants, dT " << log->dT
            << " s) on " << a.task << " with " << a.options.num_seeds << " seeds\n";
  for (size_t s = 0; s < result->comparisons.size(); ++s) {
    const auto& c = result->comparisons[s];
    const auto& sig = result->plan.signals[s];
    std::cout << "  " << sig.name << ": RMSE " << c.recorded.rmse << " " << sig.unit << ", bias "
              << c.recorded.bias << " " << sig.unit << ", lag " << c.recorded.lag
              << " s; RMSE / same plant's " << c.rmse_ratio << " (z " << c.rmse_z
              << "), increments " << c.step_ratio << " (z " << c.step_z << ")"
              << (c.flagged ? "  FLAGGED" : "") << "\n";
  }
  std::cout << (result->flagged ? "the bench differs from the simulated plant"
                                : "the bench is consistent with the simulated plant")
            << "\n  wrote " << json << ", " << csv << " and " << png << "\n";
  return exit_code::kOk;
}

}  // namespace

void AddReplayCommand(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<ReplayArgs>();
  auto* cmd = app.add_subcommand(
      "replay",
      "Drive a task's simulated plant with a bench log's recorded broadcasts and compare its "
      "force and angles with the recorded ones (RMSE, bias, lag, a figure and a JSON report); "
      "flags a bench that differs from the plant beyond the plant's own seed-to-seed spread "
      "(docs/replay.md)");
  cmd->add_option("--log", args->log, "Bench log (CSV, docs/formats/bench_log.md)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--task", args->task, "Task file whose plant the log is replayed on")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", args->out, "Directory for the outputs")->capture_default_str();
  cmd->add_option("--prefix", args->prefix,
                  "Output names <prefix>_replay.{json,csv,png} [default: the log's file stem]");
  cmd->add_option("--seeds", args->options.num_seeds, "Replays (seeds) for the plant's spread")
      ->check(CLI::Range(3, 1000))
      ->capture_default_str();
  cmd->add_option("--seed", args->options.first_seed, "First seed (then seed+1, ...)")
      ->capture_default_str();
  cmd->add_option("--max-lag", args->options.max_lag,
                  "Largest lag searched, s [default: 5 control periods]")
      ->check(NonNegative());
  cmd->add_option("--ratio-band", args->options.criterion.ratio_band,
                  "Flag when the RMSE exceeds the same plant's by this ratio (and --z-band)")
      ->check(NumberIn(1, false, 1e6, "a number >= 1"))
      ->capture_default_str();
  cmd->add_option("--step-ratio-band", args->options.criterion.step_ratio_band,
                  "... or when the increments' RMSE exceeds the same plant's by this ratio")
      ->check(NumberIn(1, false, 1e6, "a number >= 1"))
      ->capture_default_str();
  cmd->add_option("--z-band", args->options.criterion.z_band,
                  "... and (both) by this many standard deviations of the same plant's")
      ->check(NonNegative())
      ->capture_default_str();
  cmd->callback([args, &exit_code] { exit_code = RunReplayCommand(*args); });
}

}  // namespace recruit::cli
