// `recruit plot`: the paper-style figures of one `recruit simulate` run (docs/plotting.md).
#include <iostream>
#include <memory>

#include "cli/command_modules.h"
#include "cli/commands.h"
#include "common/exit_codes.h"
#include "plot/plot_run.h"

namespace recruit::cli {

void AddPlotCommand(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<plot::PlotOptions>();
  auto* cmd = app.add_subcommand(
      "plot",
      "Plot a run of `recruit simulate`: force (or angle) vs reference, true vs estimated "
      "on-count with the filter's +-2 sd band, broadcast probabilities, mean unit temperature, "
      "and all panels in one figure. PNG and/or SVG (docs/plotting.md).");
  auto* csv = cmd->add_option("--csv", o->csv, "The run's per-step CSV (<name>_steps.csv)");
  auto* map = cmd->add_option(
      "--stability-map", o->stability_map,
      "Instead of --csv: a `recruit sweep` directory's stability.dat; draws the dT x lambda map "
      "of mean overshoot as <out>/<name>.<format> (name default: stability)");
  csv->excludes(map);
  map->excludes(csv);
  cmd->add_option("--summary", o->summary,
                  "The run's summary (<name>_summary.json): title line (task, estimator, dT, "
                  "lambda, seed) and the tracked unit");
  cmd->add_option("--out", o->out_dir, "Output directory (created if missing)")->required();
  cmd->add_option(
      "--name", o->name,
      "File name prefix (default: the CSV's name without _steps.csv); files are "
      "<name>_{tracking,forces,count,broadcast,temperature,all}.<format> (forces: angle "
      "tasks only)");
  cmd->add_option("--format", o->formats, "png, svg or png,svg")->capture_default_str();
  cmd->add_option("--width", o->width, "Width of each figure, px")->capture_default_str();
  cmd->add_option("--height", o->height,
                  "Height of each single figure, px (the combined figure: 0.55x per panel, 1x "
                  "per panel below 640 px wide)")
      ->capture_default_str();
  cmd->add_option("--figure", o->figure,
                  "Only this figure (tracking, forces, count, broadcast, temperature, all), "
                  "written as <out>/<name>.<format>");
  cmd->add_option(
         "--panel", o->panels,
         "Column mode, for any numeric CSV: one panel per use, 'LABEL=COL[*SCALE][,COL...]' "
         "(e.g. 'force (N)=tension,on*0.5'); writes <out>/<name>.<format>")
      ->type_name("SPEC");
  cmd->add_option("--x", o->x, "Column mode: the x column")->capture_default_str();
  cmd->add_option("--x-label", o->x_label, "Column mode: the x axis label")->capture_default_str();
  cmd->add_option("--title", o->title, "Column mode: a title line above the panels");
  cmd->callback([o, &exit_code] {
    if (o->csv.empty() && o->stability_map.empty()) {
      std::cerr << "recruit plot: give --csv FILE (a run or any numeric CSV) or --stability-map "
                   "FILE\n";
      exit_code = exit_code::kUsage;
      return;
    }
    // The drawing code (cairo) is loaded only now (cli/command_modules.h).
    std::string error;
    const PlotModule* module = OpenPlotModule(&error);
    if (!module) {
      std::cerr << "recruit plot: " << error << "\n";
      exit_code = exit_code::kIo;
      return;
    }
    std::vector<std::string> written;
    Error failed;
    module->run(o.get(), &written, &failed);
    if (!failed.message.empty()) {
      exit_code = Fail("plot", failed);
      return;
    }
    for (const auto& p : written) std::cout << p << "\n";
    exit_code = 0;
  });
}

}  // namespace recruit::cli
