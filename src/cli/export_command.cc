// recruit export --task T [--dT S --lambda L --estimator E | --sweep DIR] --out DIR: the task's
// tuned controller as a C99 package for a microcontroller (recruit_controller.h/.c) and the
// unit side with the broadcast's wire format (recruit_unit.h/.c), docs/export.md.
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "cli/commands.h"
#include "cli/errors.h"
#include "common/atomic_file.h"
#include "common/output_path.h"
#include "export/controller_export.h"
#include "export/sweep_choice.h"
#include "sim/run_task.h"

namespace recruit::cli {
namespace {

struct ExportArgs {
  std::string task, out, sweep, precision = "float";
  int plant_point = -1;  // with --sweep over plant axes
  sim::RunOptions run;
};

int RunExport(const ExportArgs& a) {
  const std::string cmd = "export";
  auto precision = exporter::ParsePrecision(a.precision);
  if (!precision) return Fail(cmd, "--precision: " + precision.error(), exit_code::kUsage);
  auto task = sim::Task::FromFile(a.task);
  if (!task.ok()) return Fail(cmd, task.failure());
  sim::RunOptions run = a.run;
  nlohmann::json sweep_note;  // export.json's "sweep" with plant axes
  if (!a.sweep.empty()) {
    const sim::ControllerSettings s = sim::EffectiveSettings(*task, run);
    auto choice = exporter::SweepChoice(a.sweep, *task, s.estimator, a.plant_point);
    if (!choice) return Fail(cmd, choice.failure().In("--sweep: "));
    run.dT = choice->dT;
    run.lambda = choice->lambda;
    std::string point;
    if (choice->plant_task) {
      // The controller of the sweep's plant at that point: its task and model.
      task = std::move(*choice->plant_task);
      nlohmann::json values = nlohmann::json::object();
      point = " at plant point " + std::to_string(choice->plant_point) + " (";
      for (const auto& [name, v] : choice->plant_values) {
        values[name] = v;
        char num[32];
        std::snprintf(num, sizeof num, "%g", v);
        point += (point.back() == '(' ? "" : ", ") + name + " " + num;
      }
      point += ")";
      sweep_note = {{"folder", a.sweep},
                    {"plant_point", choice->plant_point},
                    {"plant_values", values},
                    {"model", task->model_path}};
    }
    std::cout << "sweep " << a.sweep << " recommends dT " << choice->dT << " s, lambda "
              << choice->lambda << " for " << s.estimator << point << " (" << choice->why << ")\n";
  }
  const sim::ControllerSettings settings = sim::EffectiveSettings(*task, run);
  const std::vector<std::pair<std::string, std::string>> inputs = {
      {"--task", a.task},
      {"the task's model", task->model_path},
      {"the filter model", settings.filter_model}};
  auto pkg = exporter::ExportController(*task, run, *precision);
  if (!pkg.ok()) return Fail(cmd, pkg.failure());
  if (!sweep_note.is_null()) {
    for (exporter::ExportedFile& f : pkg->files) {
      if (f.name != "export.json") continue;
      nlohmann::json m = nlohmann::json::parse(f.contents);
      m["sweep"] = sweep_note;
      f.contents = m.dump(2) + "\n";
    }
  }
  const std::filesystem::path out(a.out);
  for (const exporter::ExportedFile& f : pkg->files) {
    if (Status s = CheckNotAnInput((out / f.name).string(), "--out", inputs); !s.ok()) {
      return Fail(cmd, s.error(), exit_code::kUsage);
    }
  }
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec) {
    return Fail(cmd, "cannot create --out '" + ShortText(a.out) + "': " + ec.message(),
                exit_code::kIo);
  }
  // Every file is written to its temporary sibling first; only when all are written are they
  // renamed into place (a failure leaves none of them).
  std::vector<std::unique_ptr<AtomicFile>> files;
  for (const exporter::ExportedFile& f : pkg->files) {
    files.push_back(std::make_unique<AtomicFile>((out / f.name).string(), std::ios::binary));
    if (!files.back()->ok()) return Fail(cmd, files.back()->error(), exit_code::kIo);
    files.back()->stream() << f.contents;
    files.back()->stream().flush();
    if (!files.back()->stream()) {
      return Fail(cmd, "cannot write '" + ShortText(files.back()->path()) + "'", exit_code::kIo);
    }
  }
  for (auto& f : files) {
    if (Status s = f->Commit(); !s.ok()) return Fail(cmd, s.error(), exit_code::kIo);
  }
  std::cout << pkg->summary << "\nwrote";
  for (const exporter::ExportedFile& f : pkg->files) std::cout << " " << f.name;
  std::cout << " in " << a.out << "\n";
  return exit_code::kOk;
}

}  // namespace

void AddExportCommand(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<ExportArgs>();
  args->run.identify_missing_models = true;  // as simulate: a missing model is identified
  auto* cmd = app.add_subcommand(
      "export",
      "Write the task's tuned controller as a self-contained C99 package for a microcontroller "
      "(recruit_controller.h/.c: estimator, expectation law, outer loop) and the unit side "
      "with the broadcast's wire format (recruit_unit.h/.c); docs/export.md");
  cmd->add_option("--task", args->task, "Task file (JSON, docs/formats/task.md)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", args->out, "Directory for the package")->required();
  auto* dT = cmd->add_option_function<double>(
                    "--dT", [a = args.get()](double v) { a->run.dT = v; },
                    "Sampling period, s (> 0) [default: the task file's]")
                 ->type_name("SECONDS")
                 ->check(Positive());
  auto* lambda = cmd->add_option_function<double>(
                        "--lambda", [a = args.get()](double v) { a->run.lambda = v; },
                        "Gain of the expectation law, in (0, 1] [default: the task file's]")
                     ->type_name("GAIN")
                     ->check(Fraction());
  cmd->add_option_function<std::string>(
         "--estimator", [a = args.get()](const std::string& v) { a->run.estimator = v; },
         "output, kalman2 or kalman-augmented [default: the task file's]")
      ->type_name("NAME");
  cmd->add_option_function<std::string>(
         "--filter-model", [a = args.get()](const std::string& v) { a->run.filter_model = v; },
         "Filter model file for kalman-augmented [default: the task file's, else the one "
         "identified for the bundle and dT]")
      ->type_name("FILE")
      ->check(CLI::ExistingFile);
  auto* sweep =
      cmd->add_option("--sweep", args->sweep,
                      "A `recruit sweep` output folder of this task: export with the dT and lambda "
                      "its report recommends for the estimator")
          ->type_name("DIR")
          ->check(CLI::ExistingDirectory)
          ->excludes(dT)
          ->excludes(lambda);
  cmd->add_option("--plant-point", args->plant_point,
                  "With a --sweep over plant axes: export for the sweep's plant at this point "
                  "(table.md's plant column): its task and model with the point's values, and "
                  "the dT and lambda recommended there")
      ->type_name("K")
      ->check(CLI::NonNegativeNumber)
      ->needs(sweep);
  cmd->add_option("--precision", args->precision, "double or float")
      ->capture_default_str()
      ->check(CLI::IsMember({"double", "float"}));
  cmd->callback([args, &exit_code] { exit_code = RunExport(*args); });
}

}  // namespace recruit::cli
