// recruit sil --task T: the simulated plant, paced against the wall clock, in the loop with an
// external controller (a native build of `recruit export`'s package, or firmware) over a
// pseudo-terminal or UDP on the loopback address; docs/sil.md.
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>

#include "cli/commands.h"
#include "cli/errors.h"
#include "cli/run_options.h"
#include "common/atomic_file.h"
#include "common/output_path.h"
#include "sil/sil_hook.h"
#include "sim/run_task.h"

namespace recruit::cli {
namespace {

struct SilArgs {
  std::string task, out = ".", summary;
  std::string link = "udp", bind = "127.0.0.1", pty_link, speed = "1";
  int port = 0;
  sil::SilOptions sil;
  sim::RunOptions run;
};

// "max" or 0: unpaced; else a finite factor > 0.
Result<double> ParseSpeed(const std::string& s) {
  if (s == "max") return 0.0;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || !std::isfinite(v) || v < 0) {
    return Error{"--speed '" + ShortText(s) + "': must be a number >= 0 or max"};
  }
  return v;
}

void PrintCounters(const sil::SilCounters& c) {
  std::cout << "  link: " << c.instants << " measurements sent, " << c.applied
            << " commands applied, " << c.lost << " lost (last command held), " << c.late
            << " late, " << c.replayed << " replayed, " << c.unexpected << " unexpected, "
            << c.refused.malformed << " malformed, " << c.refused.truncated << " truncated, "
            << c.refused.oversized << " oversized, " << c.refused.foreign << " foreign, "
            << c.refused.junk_bytes << " junk bytes; " << c.overruns << " overruns; answer "
            << "latency mean " << (c.applied > 0 ? 1e3 * c.latency_sum / c.applied : 0.0)
            << " ms, max " << 1e3 * c.latency_max << " ms\n";
}

int RunSil(const SilArgs& a) {
  const std::string cmd = "sil";
  auto speed = ParseSpeed(a.speed);
  if (!speed.ok()) return Fail(cmd, speed.error(), exit_code::kUsage);
  auto task = sim::Task::FromFile(a.task);
  if (!task.ok()) return Fail(cmd, task.failure());
  if (task->auto_loop) {  // before anything listens: the firmware would drive only the force
    return Fail(
        cmd,
        a.task +
            ": \"outer_loop\": \"auto\" is not driven over the SIL link (it sets "
            "every bundle's force reference from the joints' angles inside recruit); "
            "give the task hand-set gains (docs/sil.md), or run the self-tuned loop's package with "
            "`recruit export` (docs/export.md)",
        exit_code::kBadInput);
  }
  if (a.summary.empty()) {
    if (Status s = CheckFileNameComponent(task->name, a.task + ": name"); !s.ok()) {
      return Fail(cmd, s.error(), exit_code::kBadInput);
    }
  }
  const std::string summary =
      a.summary.empty()
          ? (std::filesystem::path(a.out) / (task->name + "_sil_summary.json")).string()
          : a.summary;
  const sim::ControllerSettings settings = sim::EffectiveSettings(*task, a.run);
  if (Status s = CheckNotAnInput(summary, "--summary",
                                 {{"--task", a.task},
                                  {"the task's model", task->model_path},
                                  {"the filter model", settings.filter_model}});
      !s.ok()) {
    return Fail(cmd, s.error(), exit_code::kUsage);
  }
  std::error_code ec;
  std::filesystem::create_directories(a.out, ec);
  if (ec) {
    return Fail(cmd, "cannot create --out '" + ShortText(a.out) + "': " + ec.message(),
                exit_code::kIo);
  }
  AtomicFile summary_file(summary, std::ios::binary);
  if (!summary_file.ok()) return Fail(cmd, summary_file.error(), exit_code::kIo);

  auto transport = a.link == "pty" ? sil::OpenPty(a.pty_link) : sil::OpenUdp(a.bind, a.port);
  if (!transport.ok()) return Fail(cmd, transport.error(), exit_code::kIo);
  sil::SilOptions options = a.sil;
  options.speed = *speed;
  sil::SilHook hook(**transport, options, settings.dT);
  // The line a controller (or a test) waits for: where to connect.
  std::cout << "recruit sil: listening on " << (*transport)->Describe() << std::endl;

  sim::RunOptions run = a.run;
  run.control_hook = &hook;
  auto result = sim::RunTask(*task, run);
  hook.Finish();
  if (hook.timed_out()) {
    PrintCounters(hook.counters());
    return Fail(cmd, result.ok() ? "the controller timed out" : result.error(),
                exit_code::kNoController);
  }
  if (!result.ok()) return Fail(cmd, result.failure());
  nlohmann::json j = result->ToJson();
  j["sil"] = hook.counters().ToJson();
  j["sil"]["link"] = (*transport)->Describe();
  j["sil"]["speed"] = *speed;
  j["sil"]["deadline"] = hook.deadline();
  summary_file.stream() << j.dump(2) << "\n";
  if (Status s = summary_file.Commit(); !s.ok()) return Fail(cmd, s.error(), exit_code::kIo);
  const auto& m = result->metrics;
  std::cout << "task " << result->task << ", dT " << result->dT << " s, seed " << result->seed
            << "\n  tracking RMSE " << m.tracking_rmse << " " << result->unit << ", IAE " << m.iae
            << ", switching " << m.switching_rate << " /unit/s, estimator RMSE " << m.estimator_rmse
            << " units\n  " << result->duration << " s simulated in " << result->wall_seconds
            << " s\n";
  PrintCounters(hook.counters());
  std::cout << "  wrote " << summary << "\n";
  return exit_code::kOk;
}

}  // namespace

void AddSilCommand(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<SilArgs>();
  auto* cmd = app.add_subcommand(
      "sil",
      "Software in the loop: run the task's simulated plant paced against the wall clock and "
      "let an external controller (e.g. a native build of `recruit export`'s package) close the "
      "loop over UDP or a pseudo-terminal; docs/sil.md. Exit 6: no controller connected (or it "
      "fell silent) within --connect-timeout");
  cmd->add_option("--task", args->task, "Task file (JSON, docs/formats/task.md)")
      ->required()
      ->check(CLI::ExistingFile);
  AddRunOptions(cmd, &args->run);
  cmd->add_option("--link", args->link, "udp or pty")
      ->capture_default_str()
      ->check(CLI::IsMember({"udp", "pty"}));
  cmd->add_option("--bind", args->bind, "UDP: IPv4 address to listen on")->capture_default_str();
  cmd->add_option("--port", args->port, "UDP: port to listen on (0: one the system picks)")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  cmd->add_option("--pty-link", args->pty_link,
                  "pty: also make this path a symbolic link to the pseudo-terminal's device")
      ->type_name("PATH");
  cmd->add_option("--speed", args->speed,
                  "Simulated seconds per wall-clock second (10: ten times real time); 0 or max: "
                  "as fast as the controller answers")
      ->capture_default_str();
  cmd->add_option("--deadline", args->sil.deadline,
                  "Wall seconds a command may take after its measurement [default: half a "
                  "period at --speed; 1 s unpaced]")
      ->type_name("SECONDS")
      ->check(Positive());
  cmd->add_option("--connect-timeout", args->sil.connect_timeout,
                  "Wall seconds to wait for the controller's hello, and the longest silence "
                  "after it, before giving up (exit 6)")
      ->type_name("SECONDS")
      ->capture_default_str()
      ->check(Positive());
  cmd->add_option("--out", args->out, "Directory for the summary")->capture_default_str();
  cmd->add_option("--summary", args->summary,
                  "JSON summary [default: OUT/<task name>_sil_summary.json]");
  cmd->callback([args, &exit_code] { exit_code = RunSil(*args); });
}

}  // namespace recruit::cli
