// TelemetryPlots: the scrolling plots drawn beside the scene with MuJoCo's mjvFigure, stacked
// panels sharing the time axis:
//   - force task: force and its reference (N); angle task: joint angle and its reference (deg),
//     then each bundle's force with the force reference its controller tracks (N);
//   - each bundle's true on-count (solid stairs) and the estimator's count (dashed, lighter) with
//     the filter's estimated_on +- 2 estimated_on_std band (translucent, under the lines), and
//     for a bundle whose units can fail the units still working (grey stairs); the count axis
//     starts at zero.
// Rules (tests/render/telemetry_plots_test.cc): the legend sits in its own strip above each
// panel, never over data; ticks are integer multiples of a 1-2-5 x 10^k step with the units in
// the panel title; the whole window is kept however long it is (each line is thinned to fit
// mjvFigure's 1000-point cap, keeping every bucket's min and max); sizes follow the font.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "common/telemetry.h"
#include "render/unit_counts.h"

namespace recruit::render {

enum class LineStyle { kSolid, kStairs, kDashed };

struct PlotLine {
  std::string name;  // legend entry
  std::array<float, 3> rgb{};
  LineStyle style = LineStyle::kSolid;
  std::deque<double> t, y;  // the window's samples (non-finite values left out)
};

// A panel's y axis, shared by everything drawn on it: values map linearly to [0, 1], bottom to
// top of the pane. The curves go to mjvFigure already mapped, with the range [0, 1], because
// MuJoCo 4's mjr_figure widens a y range to multiples of 10^floor(log10(span)) (e.g.
// [-50, 50] to [-100, 100]) and would draw the curves on another scale than the labels; [0, 1]
// it keeps. The labels and bands are placed through the same map.
struct AxisMap {
  double lo = 0, hi = 1;  // the first and last tick
  double ToUnit(double v) const { return (v - lo) / (hi - lo); }
  double FromUnit(double u) const { return lo + u * (hi - lo); }
};

struct PlotBand {
  std::string name;
  std::array<float, 4> rgba{};
  std::deque<double> t, lo, hi;
  bool had_data = false;  // has had a sample (its legend entry stays from then on)
};

// Text measures of the font the plots are drawn with (from the mjrContext, or fixed in tests).
struct TextMetrics {
  int char_height = 16;
  std::function<int(const std::string&)> width;  // pixels of a string
  static TextMetrics FromContext(const mjrContext* con);
};

class TelemetryPlots {
 public:
  // `window` is the time span shown, s (> 0): older points scroll out on the left. The axis
  // runs between round ticks, so up to one tick step more than `window` is shown.
  explicit TelemetryPlots(double window);

  // Appends one sample. The panels are chosen at the first sample (its reference unit and
  // bundles).
  void Add(const TelemetrySample& sample);
  // The same with each bundle's working/open/stuck counts (UnitCountReader): a bundle that has
  // them at the first sample gets a "working" line (stairs) in the units panel, the units still
  // working against the total of the axis.
  void Add(const TelemetrySample& sample, const std::vector<std::optional<UnitCounts>>& counts);

  struct PanelBoxes {
    mjrRect legend;  // the legend strip (may have height 0 when the panel has no lines)
    mjrRect figure;  // the mjvFigure's rectangle (title, ticks, data)
  };
  // Where each panel's legend and figure go in `area` (pixels, bottom-left origin).
  std::vector<PanelBoxes> Layout(mjrRect area, const TextMetrics& text) const;
  // Fills every figure for drawing in `area`: x and y ranges on round ticks, thinned lines.
  void Prepare(mjrRect area, const TextMetrics& text);
  // Prepare, then draws the legends, the figures and the bands. Call between mjr_render and
  // mjr_readPixels. Line widths scale with con->fontScale.
  void Draw(mjrRect area, const mjrContext* con);

  int num_panels() const { return static_cast<int>(panels_.size()); }
  const mjvFigure& figure(int panel) const { return *panels_[panel].fig; }
  // The dashed lines are drawn by a second, overlaid figure in barplot mode (segments).
  const mjvFigure& dashes(int panel) const { return *panels_[panel].dash; }
  const std::vector<PlotLine>& lines(int panel) const { return panels_[panel].lines; }
  const std::vector<PlotBand>& bands(int panel) const { return panels_[panel].bands; }
  // Tick values of the last Prepare (x then y).
  const std::vector<double>& x_ticks() const { return x_ticks_; }
  const std::vector<double>& y_ticks(int panel) const { return panels_[panel].y_ticks; }
  // The y tick labels of the last Prepare (drawn by this class).
  const std::vector<std::string>& y_labels(int panel) const { return panels_[panel].y_labels; }
  // The y axis of the last Prepare (the ticks' range) that the figure's y values are mapped by.
  const AxisMap& y_axis(int panel) const { return panels_[panel].y_axis; }
  // The pixel row (bottom-left origin) where a drawn figure puts the mapped value `unit`, from
  // what mjr_figure reports (yaxisdata, yaxispixel): the labels and bands use it.
  static double UnitToRow(const mjvFigure& fig, double unit);
  // The x tick labels mjr_figure prints: evenly spaced values between the range ends,
  // interpolated in float and formatted with the figure's xformat.
  static std::vector<std::string> XTickLabels(const mjvFigure& fig);

  static constexpr int kMaxBundles = 4;  // bundles drawn

 private:
  struct Panel {
    std::string title;  // with the unit
    std::vector<PlotLine> lines;
    std::vector<PlotBand> bands;
    std::unique_ptr<mjvFigure> fig, dash;
    std::vector<double> y_ticks;
    std::vector<std::string> y_labels;
    AxisMap y_axis;
    bool include_zero = true;
    bool counts = false;  // unit counts: the axis starts at zero (a band below it is clipped)
  };
  void Configure(const TelemetrySample& s, const std::vector<std::optional<UnitCounts>>& counts);
  void Drop(double start);
  int LegendRows(const Panel& p, int width, const TextMetrics& text) const;
  void DrawLegend(const Panel& p, mjrRect box, const mjrContext* con, const TextMetrics& text,
                  float line_px) const;
  void DrawBands(const Panel& p, const mjrContext* con) const;
  void DrawYLabels(const Panel& p, const mjrContext* con, const TextMetrics& text) const;

  double window_;
  double now_ = 0;
  bool configured_ = false;
  bool angle_ = false;
  std::vector<Panel> panels_;
  std::vector<int> working_line_;  // per bundle: its "working" line in the units panel, or -1
  std::vector<double> x_ticks_;
};

}  // namespace recruit::render
