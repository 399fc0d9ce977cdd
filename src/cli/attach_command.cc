// recruit attach MODEL.xml --muscles NAME[,NAME...] -o OUT.xml: a model's muscles become sized
// recruit.sma bundles (src/attach/attach.h); prints what it changed and the design.
#include <filesystem>
#include <iostream>
#include <sstream>

#include "attach/attach.h"
#include "attach/report.h"
#include "cli/commands.h"
#include "cli/errors.h"

namespace recruit::cli {
namespace {

std::vector<std::string> SplitList(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

bool SameFile(const std::string& a, const std::string& b) {
  std::error_code ec;
  namespace fs = std::filesystem;
  return fs::weakly_canonical(fs::absolute(a, ec), ec) ==
         fs::weakly_canonical(fs::absolute(b, ec), ec);
}

struct AttachArgs {
  attach::AttachOptions options;
  std::string muscles, lock;
};

int RunAttach(AttachArgs& a) {
  const std::string cmd = "attach";
  attach::AttachOptions& o = a.options;
  o.muscles = SplitList(a.muscles);
  o.lock = SplitList(a.lock);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(o.model, ec)) {
    return Fail(cmd, "cannot open model '" + o.model + "': no such file", exit_code::kUsage);
  }
  if (o.muscles.empty()) return Fail(cmd, "--muscles names no actuator", exit_code::kUsage);
  if (!o.size_only && o.output.empty()) {
    return Fail(cmd, "-o OUT.xml is required (or --size-only)", exit_code::kUsage);
  }
  for (const auto& [label, path] :
       {std::pair{"-o", o.output}, std::pair{"--task", o.task}, std::pair{"--report", o.report}}) {
    if (!path.empty() && SameFile(path, o.model)) {
      return Fail(
          cmd,
          std::string(label) + " '" + path + "' is the input model: refusing to overwrite an input",
          exit_code::kUsage);
    }
  }
  auto report = attach::Attach(o);
  if (!report.ok()) return Fail(cmd, report.failure());
  for (const std::string& line : report->changes) std::cout << "changed: " << line << "\n";
  std::cout << attach::DesignTable(*report);
  if (!report->output.empty()) std::cout << "wrote " << report->output << "\n";
  if (!report->task.empty()) std::cout << "wrote " << report->task << "\n";
  if (!o.report.empty()) std::cout << "wrote " << o.report << "\n";
  return exit_code::kOk;
}

}  // namespace

void AddAttachCommand(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<AttachArgs>();
  CLI::App* sub = app.add_subcommand(
      "attach",
      "Turn a MuJoCo model's muscles (or any tendon actuators) into sized recruit.sma SMA bundles "
      "on the same tendons, in a copy of the model (docs/howto-own-model.md). Exit codes: 0 ok, "
      "2 usage (missing model file, no -o, output = input), 3 bad model or name (unknown "
      "actuator, not on a tendon, lengthrange failure), 4 I/O.");
  sub->add_option("model", args->options.model, "input MJCF model")->required();
  sub->add_option("--muscles", args->muscles,
                  "actuators to replace, comma-separated, or 'all' (every muscle on a tendon)")
      ->required();
  sub->add_option("-o,--output", args->options.output, "model to write");
  sub->add_option("--task", args->options.task, "also write a starter task (JSON) for it");
  sub->add_option("--report", args->options.report, "write what changed and the design as JSON");
  sub->add_flag("--size-only", args->options.size_only, "print the design; write no model");
  sub->add_option("--force", args->options.force,
                  "peak force of every bundle (N) instead of each muscle's F0")
      ->check(NumberIn(0, true, 1e7, "a force in N"));
  sub->add_flag("--lengthrange-from-joints", args->options.lengthrange_from_joints,
                "set the lengthrange of other muscles whose MuJoCo computation fails from the "
                "joint ranges");
  sub->add_option("--lock", args->lock,
                  "joints held at their reference value in the written model (a joint equality "
                  "each) and not driven by the starter task (comma-separated)");
  sub->add_option("--max-time-constant", args->options.limits.max_time_constant,
                  "slowest unit thermal time constant (s) sizing prefers a thinner wire for, with "
                  "more wires: bandwidth against heating power")
      ->check(NumberIn(0, true, 1e3, "seconds"))
      ->capture_default_str();
  sub->add_option("--stroke-use", args->options.limits.stroke_use,
                  "fraction of a unit's stroke the tendon's excursion uses: the rest sets how "
                  "steeply a bundle's force falls as it shortens (its own stiffness)")
      ->check(NumberIn(0.2, false, 0.95, "a fraction in 0.2..0.95"))
      ->capture_default_str();
  sub->add_option("--units-per-holding-force", args->options.limits.units_per_holding_force,
                  "units whose force makes up the force that holds the limb's own weight (the "
                  "counts' resolution); 0: no such rule")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  sub->add_option("--damping-ratio", args->options.limits.damping_ratio,
                  "least damping ratio of every joint the bundles move, at their stiffness at "
                  "rest, that a damper beside each bundle gives it (a wire does not damp its "
                  "joint as a muscle does); 0: no dampers")
      ->check(NumberIn(0, false, 10, "a ratio in 0..10"))
      ->capture_default_str();
  sub->callback([args, &exit_code] { exit_code = RunAttach(*args); });
}

}  // namespace recruit::cli
