// The sweep's report a lab note can carry: report.md (tables + figure links) and report.html (the
// same, self-contained: figures embedded as PNG data), with the figures as PNG and SVG drawn by
// src/plot: margin.{png,svg} (criterion margin against dT per plant point, one panel per
// estimator, with the output-only loop's latency bound dT = lambda tau / c as dotted lines) and
// critical_dt.{png,svg} (the critical dT against each plant axis) and tracking.{png,svg} (the
// tracking RMSE at the recommended dT against each plant axis). Every file
// depends only on the runs' results, so a merged sharded sweep writes the same bytes.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "common/result.h"
#include "plot/figure.h"
#include "plot/plot_run.h"
#include "plot/render.h"
#include "sweep/grid.h"
#include "sweep/recommend.h"
#include "sweep/table.h"

namespace recruit::sweep {

struct ReportInput {
  std::string title;        // the task's name
  std::string description;  // one line: what was swept
  sweep::TrackingCriterion criterion;
  std::vector<sweep::CellStats> cells;
  // Per plant point: the agonist's force latency tau (s, sweep/latency.h; NaN = unknown). Empty:
  // no latency bound in the report.
  std::vector<double> latency;
  // Markdown appended to the report's tables (before the figures): the seeds' reasons per cell
  // (sweep/tune.h SeedReasonsMarkdown).
  std::string seed_reasons;
  // The tracked quantity's unit ("N", "rad"; "" = not said), for the tracking figure's axis.
  std::string unit;
};

// The Markdown text (figure links relative to the report); figures are listed only if made,
// stability.png (with how to read it) only if `with_stability_map`.
std::string ReportMarkdown(const ReportInput& in, const std::vector<Recommendation>& recs,
                           const std::vector<Sensitivity>& sens, bool with_figures,
                           bool with_stability_map = false);

// Draws a figure as PNG or SVG bytes: plot::RenderFigure, which `recruit` reaches through its
// plot module (cli/command_modules.h) so that only the commands that draw load cairo.
using FigureRenderer =
    std::function<Result<std::string>(const plot::Figure&, int width, int height, plot::Format)>;

// Writes report.md, report.html and the figures into `out_dir`. A sweep without plant axes whose
// `out_dir` holds stability.png (StabilityMapOptions; `recruit sweep` draws it first) gets it
// linked in report.md and embedded in report.html.
Status WriteReport(const ReportInput& in, const std::string& out_dir, const FigureRenderer& render);

// What `recruit sweep` asks `recruit plot --stability-map` for: <out_dir>/stability.png from the
// stability.dat that sweep::WriteTables wrote there (a panel of 460 x 420 px per estimator).
plot::PlotOptions StabilityMapOptions(const std::string& out_dir, const std::string& title,
                                      int num_estimators);

}  // namespace recruit::sweep
