// The work of `recruit plot` (src/cli/plot_command.cc is its command-line glue): validate the
// options, read the run, build and render every figure in memory, and only then write the files
// (each through a temporary file renamed into place). Any error: a message naming the file,
// column or option and the value; nothing written.
#pragma once

#include <string>
#include <vector>

#include "common/result.h"

namespace recruit::plot {

inline constexpr int kMinWidth = 240, kMinHeight = 180, kMaxSide = 8192;

struct PlotOptions {
  std::string csv;              // the run's `<name>_steps.csv`
  std::string summary;          // its `<name>_summary.json`; empty = no title line
  std::string out_dir;          // created if missing
  std::string name;             // file name prefix; empty = the CSV's name without "_steps.csv"
  std::string formats = "png";  // comma-separated: png, svg
  // Of each single figure; the combined one is 0.55 x height per panel (2.2 x for 4 panels),
  // 1 x height per panel when width < 640 px.
  int width = 1000, height = 600;
  // Only this figure (tracking, forces, count, broadcast, temperature or all), written as
  // `<out_dir>/<name>.<format>`; empty = every figure, `<name>_<figure>.<format>`.
  std::string figure;
  // Column mode (any numeric CSV): one figure `<out_dir>/<name>.<format>` with a panel per
  // spec "LABEL=COL[*SCALE][,COL...]" (column_figure.h) against column `x`.
  std::vector<std::string> panels;
  std::string x = "time";
  std::string x_label = "time (s)";
  std::string title;  // column mode's (and the stability map's) title line; empty = none
  // Stability map mode: `recruit sweep`'s stability.dat instead of --csv; writes
  // <out_dir>/<name>.<format> (stability_map.h).
  std::string stability_map;
};

// Writes <out_dir>/<name>_<figure>.<format> for figure in tracking, forces (angle tasks),
// count, broadcast, temperature, all (or, in column mode, <out_dir>/<name>.<format>); returns
// the paths written.
Result<std::vector<std::string>> RunPlot(const PlotOptions& options);

}  // namespace recruit::plot
