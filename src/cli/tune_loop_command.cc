// recruit tune-loop --task FILE: the self-tuned outer loop's design for an angle task
// ("outer_loop": "auto"): per driven joint and reference pose, the model (inertia, damping,
// stiffness, the bundles' tension response), the gains, and the predicted step response.
#include <cstdio>
#include <iostream>

#include "cli/commands.h"
#include "cli/errors.h"
#include "cli/run_options.h"
#include "sim/joint_loop.h"
#include "sim/run_task.h"

namespace recruit::cli {
namespace {

struct TuneLoopArgs {
  std::string task;
  bool response = false;
  sim::RunOptions run;
};

void PrintDesign(const sim::JointDesignRecord& r, bool response) {
  const control::LoopDesign& d = r.design;
  std::printf(
      "%-14s %8.2f  I %.3g kg m2, b %.3g N m s/rad, k %.3g N m/rad (bundles' %.3g), bundles' t63 "
      "%.2f s\n"
      "%-14s %8s  kp %.4g N m/rad, ki %.4g N m/(rad s), kd %.4g N m s/rad\n"
      "%-14s %8s  predicted: overshoot %.1f %%, settles in %.1f s%s; 1.5x slower bundles and "
      "1.5x gain: overshoot %.1f %%, %s; one sampling period late: overshoot %.1f %%, %s%s\n",
      r.joint.c_str(), r.reference * 180 / M_PI, r.dynamics.inertia, r.dynamics.damping,
      r.dynamics.stiffness, r.bundle_stiffness, r.actuator_t63, "", "", d.gains.kp, d.gains.ki,
      d.gains.kd, "", "", 100 * d.nominal.overshoot, d.nominal.settling_time,
      d.nominal.settled ? "" : " (not settled)", 100 * d.robust.overshoot,
      d.robust.settled ? "settles" : "does not settle", 100 * d.delayed.overshoot,
      d.delayed.settled ? "settles" : "does not settle",
      d.meets ? "" : ("  [" + d.note + "]").c_str());
  // The same gains as the joint will move the demand: each way through the bundles that move
  // it that way, rising or releasing (JointLoops::BothWays).
  const control::PredictedStep w =
      control::PredictStep(r.dynamics, r.both_ways, r.dT, d.gains, r.target);
  std::printf(
      "%-14s %8s  each way through its bundles' rise or release (t63 %.2f s the step's way, "
      "%.2f s back): overshoot %.1f %%, ",
      "", "", r.both_ways.TimeTo(0.63), r.release_t63, 100 * w.overshoot);
  if (w.settled) {
    std::printf("settles in %.1f s\n", w.settling_time);
  } else {
    std::printf("does not settle\n");
  }
  std::printf("%-14s %8s  one more unit on moves it", "", "");
  for (size_t i = 0; i < r.unit_angle.size(); ++i) {
    std::printf("%s %s %.3g deg", i ? "," : "", r.unit_angle[i].first.c_str(),
                r.unit_angle[i].second * 180 / M_PI);
  }
  std::printf("; the settling band of this step is +-%.3g deg\n",
              r.target.band * r.step * 180 / M_PI);
  if (!response) return;
  std::printf("%-14s %8s  step response (fraction of the step) at t = 0, dT, ...:", "", "");
  for (double y : d.nominal.angle) std::printf(" %.3f", y);
  std::printf("\n%-14s %8s  each way through its bundles' rise or release:", "", "");
  for (double y : w.angle) std::printf(" %.3f", y);
  std::printf("\n");
}

int RunTuneLoop(const TuneLoopArgs& a) {
  const std::string cmd = "tune-loop";
  auto task = sim::Task::FromFile(a.task);
  if (!task.ok()) return Fail(cmd, task.failure());
  auto designs = sim::DesignTaskLoops(*task, a.run);
  if (!designs.ok()) return Fail(cmd, designs.failure());
  const sim::ControllerSettings s = sim::EffectiveSettings(*task, a.run);
  std::printf(
      "task %s: dT %g s, lambda %g, estimator %s; target: overshoot <= 5 %%, settle into "
      "+-%g %% within the shortest hold\n%-14s %8s\n",
      task->name.c_str(), s.dT, s.lambda, s.estimator.c_str(), 100 * task->settle_band, "joint",
      "ref/deg");
  for (const sim::JointDesignRecord& r : *designs) PrintDesign(r, a.response);
  return exit_code::kOk;
}

}  // namespace

void AddTuneLoopCommand(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<TuneLoopArgs>();
  auto* cmd = app.add_subcommand(
      "tune-loop",
      "Design the outer loop of an angle task with \"outer_loop\": \"auto\" from the model and "
      "print the gains and the predicted step response at each reference pose");
  cmd->add_option("--task", args->task, "Task file (JSON, docs/formats/task.md)")
      ->required()
      ->check(CLI::ExistingFile);
  AddRunOptions(cmd, &args->run);
  cmd->add_flag("--response", args->response,
                "Also print each predicted step response at the control instants");
  cmd->callback([args, &exit_code] { exit_code = RunTuneLoop(*args); });
}

}  // namespace recruit::cli
