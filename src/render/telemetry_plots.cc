#include "render/telemetry_plots.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "plot/decimate.h"
#include "plot/ticks.h"

namespace recruit::render {
namespace {

constexpr float kBundleRgb[TelemetryPlots::kMaxBundles][3] = {
    {1.0f, 0.55f, 0.1f}, {0.3f, 0.75f, 1.0f}, {0.6f, 1.0f, 0.3f}, {1.0f, 0.4f, 0.8f}};

std::array<float, 3> Rgb(const float* c) { return {c[0], c[1], c[2]}; }
// The estimate's colour: the bundle's hue mixed halfway to white.
std::array<float, 3> Light(const float* c) {
  return {0.5f + 0.5f * c[0], 0.5f + 0.5f * c[1], 0.5f + 0.5f * c[2]};
}

// Legend geometry: a swatch 1.6 em long, entries 0.8 em apart.
int Swatch(int ch) { return ch * 8 / 5; }
int Spacing(int ch) { return ch * 4 / 5; }

int Decimals(double step) {
  return std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
}

void StyleFigure(mjvFigure* fig, bool overlay) {
  mjv_defaultFigure(fig);
  fig->flg_legend = 0;  // the legend is drawn above the figure (DrawLegend)
  fig->flg_extend = 0;  // ranges are set on round ticks (Prepare)
  fig->flg_ticklabel[0] = 1;
  fig->flg_ticklabel[1] = 1;
  fig->flg_barplot = overlay ? 1 : 0;  // the overlay draws dashes as isolated segments
  const float figure[4] = {0.05f, 0.05f, 0.08f, overlay ? 0.f : 1.f};
  std::memcpy(fig->figurergba, figure, sizeof(figure));
  const float pane[4] = {0.12f, 0.12f, 0.16f, overlay ? 0.f : 1.f};
  std::memcpy(fig->panergba, pane, sizeof(pane));
  const float grid[3] = {0.35f, 0.35f, 0.4f};
  std::memcpy(fig->gridrgb, grid, sizeof(grid));
}

// The samples of [start, inf), thinned to at most `max_points` (each bucket's first, min, max
// and last point, so spikes and steps survive).
plot::XY Visible(const std::deque<double>& t, const std::deque<double>& y, double start, double end,
                 int max_points) {
  plot::XY v;
  for (size_t i = 0; i < t.size(); ++i) {
    if (t[i] >= start) {
      v.x.push_back(t[i]);
      v.y.push_back(y[i]);
    }
  }
  if (static_cast<int>(v.x.size()) > max_points) {
    const plot::XY thin = plot::DecimateMinMax(v.x, v.y, std::max(1, max_points / 4));
    // DecimateMinMax bins over the data's own span; guard its output size all the same.
    if (static_cast<int>(thin.x.size()) <= max_points) return thin;
    plot::XY cut;
    const double stride = static_cast<double>(thin.x.size()) / max_points;
    for (int i = 0; i < max_points; ++i) {
      const size_t k = static_cast<size_t>(i * stride);
      cut.x.push_back(thin.x[k]);
      cut.y.push_back(thin.y[k]);
    }
    return cut;
  }
  (void)end;
  return v;
}

void SetData(mjvFigure* fig, int line, const std::vector<float>& xy) {
  const int n = std::min<int>(xy.size() / 2, mjMAXLINEPNT);
  std::memcpy(fig->linedata[line], xy.data(), sizeof(float) * 2 * n);
  fig->linepnt[line] = n;
}

struct LegendEntry {
  std::string name;
  std::array<float, 4> rgba;
  int kind;  // 0 line, 1 dashed, 2 band
};

// One entry per solid line; one per dashed-line name and one for the band, in the lines' own
// colour when a single bundle is drawn, else grey (the colour then says the bundle, the style
// says what it is). A band gets an entry once it has had data.
template <typename PanelT>
std::vector<LegendEntry> Entries(const PanelT& p) {
  std::vector<LegendEntry> e;
  const std::array<float, 4> grey = {0.75f, 0.75f, 0.75f, 1.f};
  for (const PlotLine& l : p.lines) {
    if (l.style != LineStyle::kDashed)
      e.push_back({l.name, {l.rgb[0], l.rgb[1], l.rgb[2], 1.f}, 0});
  }
  for (const PlotLine& l : p.lines) {
    if (l.style != LineStyle::kDashed) continue;
    bool seen = false;
    int same = 0;
    for (const LegendEntry& x : e) seen = seen || (x.kind == 1 && x.name == l.name);
    for (const PlotLine& o : p.lines) same += o.style == LineStyle::kDashed && o.name == l.name;
    if (!seen) {
      e.push_back(
          {l.name, same > 1 ? grey : std::array<float, 4>{l.rgb[0], l.rgb[1], l.rgb[2], 1.f}, 1});
    }
  }
  int with_data = 0;
  const PlotBand* first = nullptr;
  for (const PlotBand& b : p.bands) {
    if (b.had_data) {
      ++with_data;
      if (!first) first = &b;
    }
  }
  if (first) {
    e.push_back({first->name,
                 with_data > 1 ? std::array<float, 4>{0.85f, 0.85f, 0.85f, 0.55f} : first->rgba,
                 2});
  }
  return e;
}

}  // namespace

TextMetrics TextMetrics::FromContext(const mjrContext* con) {
  TextMetrics t;
  t.char_height = con->charHeight;
  t.width = [con](const std::string& s) {
    int w = 0;
    for (unsigned char c : s)
      w += c < 127 ? con->charWidth[c] : con->charWidth[static_cast<unsigned char>('?')];
    return w;
  };
  return t;
}

TelemetryPlots::TelemetryPlots(double window) : window_(window > 0 ? window : 20.0) {}

void TelemetryPlots::Configure(const TelemetrySample& s,
                               const std::vector<std::optional<UnitCounts>>& counts_of) {
  configured_ = true;
  angle_ = s.reference_unit == "rad";
  const int nb = std::min<int>(s.bundles.size(), kMaxBundles);
  auto make_panel = [&](const std::string& title) {
    Panel p;
    p.title = title;
    p.fig = std::make_unique<mjvFigure>();
    p.dash = std::make_unique<mjvFigure>();
    StyleFigure(p.fig.get(), false);
    StyleFigure(p.dash.get(), true);
    return p;
  };
  const std::array<float, 3> white = {0.92f, 0.92f, 0.92f};
  const std::array<float, 3> red = {1.f, 0.35f, 0.25f};
  Panel tracking = make_panel(angle_ ? "joint angle (deg)" : "force (N)");
  tracking.lines.push_back({"reference", white, LineStyle::kDashed, {}, {}});
  tracking.lines.push_back({angle_ ? "angle" : "force", red, LineStyle::kSolid, {}, {}});
  panels_.push_back(std::move(tracking));
  if (angle_) {
    Panel forces = make_panel("bundle force (N)");
    for (int b = 0; b < nb; ++b) {
      const std::string& name = s.bundles[b].actuator;
      forces.lines.push_back({name, Rgb(kBundleRgb[b]), LineStyle::kSolid, {}, {}});
      forces.lines.push_back({"ref", Light(kBundleRgb[b]), LineStyle::kDashed, {}, {}});
    }
    panels_.push_back(std::move(forces));
  }
  Panel counts = make_panel("units on");
  counts.counts = true;
  for (int b = 0; b < nb; ++b) {
    const std::string name = nb > 1 ? s.bundles[b].actuator : "true";
    counts.lines.push_back({name, Rgb(kBundleRgb[b]), LineStyle::kStairs, {}, {}});
    counts.lines.push_back({"est.", Light(kBundleRgb[b]), LineStyle::kDashed, {}, {}});
    const float* c = kBundleRgb[b];
    counts.bands.push_back({"+-2 sd", {c[0], c[1], c[2], 0.4f}, {}, {}, {}});
  }
  working_line_.assign(nb, -1);
  for (int b = 0; b < nb && b < static_cast<int>(counts_of.size()); ++b) {
    if (!counts_of[b]) continue;
    working_line_[b] = static_cast<int>(counts.lines.size());
    const float* c = kBundleRgb[b];
    const std::array<float, 3> grey = {0.45f + 0.2f * c[0], 0.45f + 0.2f * c[1],
                                       0.45f + 0.2f * c[2]};
    counts.lines.push_back({nb > 1 ? s.bundles[b].actuator + " working" : "working",
                            grey,
                            LineStyle::kStairs,
                            {},
                            {}});
  }
  panels_.push_back(std::move(counts));
}

void TelemetryPlots::Add(const TelemetrySample& s) { Add(s, {}); }

void TelemetryPlots::Add(const TelemetrySample& s,
                         const std::vector<std::optional<UnitCounts>>& unit_counts) {
  if (!configured_) Configure(s, unit_counts);
  now_ = s.time;
  auto push = [&](PlotLine& l, double y) {
    if (!std::isfinite(s.time) || !std::isfinite(y)) return;
    l.t.push_back(s.time);
    l.y.push_back(y);
  };
  const double scale = angle_ ? 180.0 / M_PI : 1.0;  // angles in deg, the unit of task files
  push(panels_[0].lines[0], scale * s.reference);
  push(panels_[0].lines[1], scale * s.measured);
  const int nb = std::min<int>(s.bundles.size(), kMaxBundles);
  Panel& counts = panels_.back();
  for (int b = 0; b < nb && 2 * b + 1 < static_cast<int>(counts.lines.size()); ++b) {
    const BundleTelemetry& bt = s.bundles[b];
    if (angle_) {
      push(panels_[1].lines[2 * b], bt.force);
      push(panels_[1].lines[2 * b + 1], bt.force_reference);
    }
    push(counts.lines[2 * b], bt.true_on);
    push(counts.lines[2 * b + 1], bt.estimated_on);
    if (working_line_[b] >= 0 && b < static_cast<int>(unit_counts.size()) && unit_counts[b]) {
      push(counts.lines[working_line_[b]], unit_counts[b]->working);
    }
    if (std::isfinite(bt.estimated_on) && std::isfinite(bt.estimated_on_std)) {
      PlotBand& band = counts.bands[b];
      band.had_data = true;
      band.t.push_back(s.time);
      band.lo.push_back(bt.estimated_on - 2 * bt.estimated_on_std);
      band.hi.push_back(bt.estimated_on + 2 * bt.estimated_on_std);
    }
  }
  // The axis starts at most one tick step (<= window) before now - window.
  Drop(now_ - 2 * window_);
}

void TelemetryPlots::Drop(double start) {
  for (Panel& p : panels_) {
    for (PlotLine& l : p.lines) {
      while (!l.t.empty() && l.t.front() < start) l.t.pop_front(), l.y.pop_front();
    }
    for (PlotBand& b : p.bands) {
      while (!b.t.empty() && b.t.front() < start) {
        b.t.pop_front(), b.lo.pop_front(), b.hi.pop_front();
      }
    }
  }
}

int TelemetryPlots::LegendRows(const Panel& p, int width, const TextMetrics& text) const {
  const int ch = text.char_height;
  int rows = 1, x = 0;
  for (const LegendEntry& e : Entries(p)) {
    const int w = Swatch(ch) + ch / 4 + text.width(e.name);
    if (x > 0 && x + w > width - ch / 2) ++rows, x = 0;
    x += w + Spacing(ch);
  }
  return rows;
}

std::vector<TelemetryPlots::PanelBoxes> TelemetryPlots::Layout(mjrRect area,
                                                               const TextMetrics& text) const {
  std::vector<PanelBoxes> boxes(panels_.size(), PanelBoxes{{0, 0, 0, 0}, {0, 0, 0, 0}});
  if (panels_.empty()) return boxes;
  const int ch = text.char_height;
  // A panel needs room for its title, ticks, a few grid lines and its legend; the forces panel
  // of an angle task is left out first when the column is short.
  std::vector<int> shown;
  for (int i = 0; i < num_panels(); ++i) shown.push_back(i);
  const int row = ch + ch / 3;
  auto legend_height = [&](const Panel& p, int h) {
    return std::min(h / 2, LegendRows(p, area.width - ch, text) * row + ch / 3);
  };
  // Three panels only when each figure gets 8 rows (title, x tick labels, axis label and
  // about four grid intervals); the counts matter more than the bundle forces.
  // The lowest panel (the counts) carries the time labels and the longest legend: it gets 1.35
  // shares of the height, the others one each (they show no time tick labels).
  auto heights = [&](size_t count) {
    std::vector<int> h(count);
    const double total = (count - 1) + 1.35;
    int used = 0;
    for (size_t k = 0; k + 1 < count; ++k) {
      h[k] = static_cast<int>(area.height / total);
      used += h[k];
    }
    h[count - 1] = area.height - used;
    return h;
  };
  auto fits = [&](const std::vector<int>& set) {
    const std::vector<int> h = heights(set.size());
    for (size_t k = 0; k < set.size(); ++k) {
      if (h[k] - legend_height(panels_[set[k]], h[k]) < 8 * ch) return false;
    }
    return true;
  };
  if (angle_ && num_panels() == 3 && !fits(shown)) shown.erase(shown.begin() + 1);
  const int n = static_cast<int>(shown.size());
  const std::vector<int> hs = heights(n);
  int top = area.bottom + area.height;
  for (int k = 0; k < n; ++k) {
    const int h = hs[k];
    const int legend_h = legend_height(panels_[shown[k]], h);
    boxes[shown[k]].legend = {area.left, top - legend_h, area.width, legend_h};
    boxes[shown[k]].figure = {area.left, top - h, area.width, h - legend_h};
    top -= h;
  }
  return boxes;
}

double TelemetryPlots::UnitToRow(const mjvFigure& fig, double unit) {
  const double d0 = fig.yaxisdata[0], d1 = fig.yaxisdata[1];
  const double frac = d1 > d0 ? (unit - d0) / (d1 - d0) : unit;
  return fig.yaxispixel[0] + frac * (fig.yaxispixel[1] - fig.yaxispixel[0]);
}

std::vector<std::string> TelemetryPlots::XTickLabels(const mjvFigure& fig) {
  std::vector<std::string> labels;
  const int axis = 0;
  const int n = fig.gridsize[axis];
  const char* format = fig.xformat;
  for (int i = 0; i < n; ++i) {
    // What mjr_figure computes: range ends interpolated in float.
    const float v = fig.range[axis][0] + (fig.range[axis][1] - fig.range[axis][0]) *
                                             static_cast<float>(i) / static_cast<float>(n - 1);
    char buf[64];
    std::snprintf(buf, sizeof(buf), format, v);
    labels.emplace_back(buf);
  }
  return labels;
}

void TelemetryPlots::Prepare(mjrRect area, const TextMetrics& text) {
  if (panels_.empty()) return;
  const std::vector<PanelBoxes> boxes = Layout(area, text);
  const int ch = text.char_height;
  // x: a 1-2-5 step with labels about 5 characters apart; the axis ends on the first tick at or
  // after now and spans a whole number of steps covering the window.
  const int label_w = std::max(1, text.width("000.0"));
  const int plot_w = std::max(1, area.width - text.width("00000") - 2 * ch);
  const int target_x = std::clamp(plot_w / (2 * label_w), 2, 8);
  const double step = plot::NiceStep(window_, target_x);
  const long steps = std::max(1L, static_cast<long>(std::ceil(window_ / step - 1e-9)));
  const long k_end = std::max(steps, static_cast<long>(std::ceil(now_ / step - 1e-9)));
  const double x_end = k_end * step, x_start = (k_end - steps) * step;
  x_ticks_.clear();
  for (long k = k_end - steps; k <= k_end; ++k) x_ticks_.push_back(k * step);
  char xformat[20];
  std::snprintf(xformat, sizeof(xformat), "%%.%df", Decimals(step));
  // Dashes: on/off intervals of about 0.6 em.
  const double dash_dt = (x_end - x_start) * std::max(3.0, 0.6 * ch) / plot_w;

  // y tick labels share one width so the panels' data areas line up.
  std::string widest = "0";
  int last_shown = -1;
  for (int p = 0; p < num_panels(); ++p) {
    if (boxes[p].figure.height > 0) last_shown = p;
  }
  for (int p = 0; p < num_panels(); ++p) {
    Panel& panel = panels_[p];
    mjvFigure* fig = panel.fig.get();
    mjvFigure* dash = panel.dash.get();
    const mjrRect box = boxes[p].figure;
    // y range: every visible point and band edge, and 0 (all plotted quantities start there).
    double lo = panel.include_zero ? 0 : INFINITY, hi = panel.include_zero ? 0 : -INFINITY;
    std::vector<plot::XY> visible;
    for (const PlotLine& l : panel.lines) {
      const int cap = l.style == LineStyle::kStairs ? mjMAXLINEPNT / 2 : mjMAXLINEPNT;
      visible.push_back(Visible(l.t, l.y, x_start, x_end, cap));
      for (double y : visible.back().y) lo = std::min(lo, y), hi = std::max(hi, y);
    }
    for (const PlotBand& b : panel.bands) {
      for (size_t i = 0; i < b.t.size(); ++i) {
        if (b.t[i] < x_start) continue;
        lo = std::min(lo, b.lo[i]);
        hi = std::max(hi, b.hi[i]);
      }
    }
    if (panel.counts) lo = 0;  // counts are >= 0; the band's lower edge is clipped at 0
    if (!(hi > lo)) hi = lo + 1;
    const int plot_h = box.height - 4 * ch;
    const int target_y = std::clamp(plot_h / (2 * ch), 2, 5);
    const plot::TickSet ticks = plot::MakeTicks(lo, hi, target_y);
    panel.y_ticks = ticks.values;
    panel.y_labels = ticks.labels;
    panel.y_axis = {ticks.lo, ticks.hi};
    const AxisMap& ymap = panel.y_axis;
    for (const std::string& l : ticks.labels) {
      if (l.size() > widest.size()) widest = l;
    }
    for (mjvFigure* f : {fig, dash}) {
      std::snprintf(f->title, sizeof(f->title), "%s", panel.title.c_str());
      std::snprintf(f->xlabel, sizeof(f->xlabel), "%s", p == last_shown ? "time (s)" : "");
      // Time tick labels only under the lowest panel: the panels share the time axis.
      f->flg_ticklabel[0] = p == last_shown ? 1 : 0;
      std::snprintf(f->xformat, sizeof(f->xformat), "%s", xformat);
      // y labels are drawn by DrawYLabels (FormatTick: exact, never "-0"); mjr_figure's own
      // would print float interpolations of the range, "-0.0" where the axis crosses zero.
      // A format without a conversion prints blanks in the width `minwidth` reserves.
      std::snprintf(f->yformat, sizeof(f->yformat), " ");
      f->range[0][0] = static_cast<float>(x_start);
      f->range[0][1] = static_cast<float>(x_end);
      // y values go in mapped to [0, 1] (AxisMap): mjr_figure keeps that range as given.
      f->range[1][0] = 0.f;
      f->range[1][1] = 1.f;
      f->gridsize[0] = static_cast<int>(x_ticks_.size());
      f->gridsize[1] = static_cast<int>(ticks.values.size());
      for (int i = 0; i < mjMAXLINE; ++i) f->linepnt[i] = 0;
    }
    int solid = 0, dashed = 0;
    for (size_t i = 0; i < panel.lines.size(); ++i) {
      const PlotLine& l = panel.lines[i];
      const plot::XY& v = visible[i];
      std::vector<float> xy;
      if (l.style == LineStyle::kDashed) {
        // Resampled every dash_dt (estimates and references change in steps); every other
        // interval is drawn.
        if (v.x.empty()) {
          ++dashed;
          continue;
        }
        size_t j = 0;
        double prev = v.y[0];
        for (long k = 0;; ++k) {
          const double t0 = v.x.front() + 2 * k * dash_dt;
          const double t1 = std::min(t0 + dash_dt, v.x.back());
          if (t0 > v.x.back() || static_cast<int>(xy.size()) >= 2 * mjMAXLINEPNT - 4) break;
          while (j < v.x.size() && v.x[j] <= t0) prev = v.y[j++];
          // Each dash holds the value at its start: a jump shows as a gap, not a slant.
          const double y0 = prev;
          const auto u0 = static_cast<float>(ymap.ToUnit(y0));
          xy.insert(xy.end(), {static_cast<float>(t0), u0, static_cast<float>(t1), u0});
        }
        SetData(dash, dashed, xy);
        std::memcpy(dash->linergb[dashed], l.rgb.data(), sizeof(float) * 3);
        ++dashed;
      } else {
        for (size_t k = 0; k < v.x.size(); ++k) {
          if (l.style == LineStyle::kStairs && k > 0 && v.y[k] != v.y[k - 1]) {
            xy.push_back(static_cast<float>(v.x[k]));
            xy.push_back(static_cast<float>(ymap.ToUnit(v.y[k - 1])));
          }
          xy.push_back(static_cast<float>(v.x[k]));
          xy.push_back(static_cast<float>(ymap.ToUnit(v.y[k])));
        }
        SetData(fig, solid, xy);
        std::memcpy(fig->linergb[solid], l.rgb.data(), sizeof(float) * 3);
        ++solid;
      }
    }
  }
  // Digits as zeros: mjr_figure reserves the width of this string for the y labels.
  for (char& c : widest) c = c == '-' || c == '.' ? c : '0';
  for (Panel& panel : panels_) {
    for (mjvFigure* f : {panel.fig.get(), panel.dash.get()}) {
      std::snprintf(f->minwidth, sizeof(f->minwidth), "%s", widest.c_str());
    }
  }
}

void TelemetryPlots::DrawLegend(const Panel& p, mjrRect box, const mjrContext* con,
                                const TextMetrics& text, float line_px) const {
  const int ch = text.char_height;
  const int row = ch + ch / 3;
  int x = box.left + ch / 2, y = box.bottom + box.height - row;
  for (const LegendEntry& e : Entries(p)) {
    const int tw = text.width(e.name);
    const int sw = Swatch(ch);
    const int w = sw + ch / 4 + tw;
    if (x > box.left + ch / 2 && x + w > box.left + box.width - ch / 2) {
      x = box.left + ch / 2;
      y -= row;
    }
    if (y < box.bottom) break;
    const int mid = y + row / 2;
    const int lw = std::max(1, static_cast<int>(std::lround(line_px)));
    if (e.kind == 2) {
      mjr_rectangle({x, y + row / 6, sw, row * 2 / 3}, e.rgba[0], e.rgba[1], e.rgba[2], e.rgba[3]);
    } else if (e.kind == 1) {
      const int dash = sw / 5;
      for (int k = 0; k < 3; ++k) {
        mjr_rectangle({x + k * sw * 2 / 5, mid - lw / 2, dash, lw}, e.rgba[0], e.rgba[1], e.rgba[2],
                      1.f);
      }
    } else {
      mjr_rectangle({x, mid - lw / 2, sw, lw}, e.rgba[0], e.rgba[1], e.rgba[2], 1.f);
    }
    // mjr_label centres the text in its rectangle: a rectangle as wide as the text aligns it
    // left; alpha 0 leaves the background.
    mjr_label({x + sw + ch / 4, y, tw, row}, mjFONT_NORMAL, e.name.c_str(), 0, 0, 0, 0, 0.9f, 0.9f,
              0.9f, con);
    x += w + Spacing(ch);
  }
}

void TelemetryPlots::DrawBands(const Panel& p, const mjrContext* con) const {
  (void)con;
  const mjvFigure& f = *p.fig;
  const double x0 = f.xaxisdata[0], x1 = f.xaxisdata[1];
  const int px0 = f.xaxispixel[0], px1 = f.xaxispixel[1];
  const int py0 = f.yaxispixel[0], py1 = f.yaxispixel[1];
  if (!(x1 > x0) || !(f.yaxisdata[1] > f.yaxisdata[0]) || px1 <= px0 || py1 <= py0) return;
  auto to_px = [&](double x) { return px0 + (x - x0) / (x1 - x0) * (px1 - px0); };
  // Through the panel's axis map, clipped to the axis, like the curves.
  auto to_py = [&](double y) { return UnitToRow(f, std::clamp(p.y_axis.ToUnit(y), 0.0, 1.0)); };
  for (const PlotBand& b : p.bands) {
    // One rectangle per 2-pixel column: the envelope of the samples in it.
    const int cols = (px1 - px0 + 1) / 2;
    std::vector<double> lo(cols, INFINITY), hi(cols, -INFINITY);
    // Each sample holds until the next one (estimates change at control instants).
    for (size_t i = 0; i < b.t.size(); ++i) {
      if (b.t[i] > x1 || (i + 1 < b.t.size() && b.t[i + 1] < x0)) continue;
      const int c0 = std::clamp(static_cast<int>((to_px(b.t[i]) - px0) / 2), 0, cols - 1);
      const int c1 =
          i + 1 < b.t.size()
              ? std::clamp(static_cast<int>((to_px(b.t[i + 1]) - px0) / 2) - 1, c0, cols - 1)
              : c0;
      for (int c = c0; c <= c1; ++c) {
        lo[c] = std::min(lo[c], b.lo[i]);
        hi[c] = std::max(hi[c], b.hi[i]);
      }
    }
    for (int c = 0; c < cols; ++c) {
      if (!(hi[c] >= lo[c])) continue;
      const int ylo = static_cast<int>(std::floor(to_py(lo[c])));
      const int yhi = static_cast<int>(std::ceil(to_py(hi[c])));
      mjr_rectangle({px0 + 2 * c, ylo, 2, std::max(1, yhi - ylo)}, b.rgba[0], b.rgba[1], b.rgba[2],
                    b.rgba[3]);
    }
  }
}

void TelemetryPlots::DrawYLabels(const Panel& p, const mjrContext* con,
                                 const TextMetrics& text) const {
  const mjvFigure& f = *p.fig;
  const int n = static_cast<int>(p.y_labels.size());
  if (n < 2) return;
  const int ch = text.char_height;
  for (int i = 0; i < n; ++i) {
    // Where the curves put the tick's value (the grid line of tick i when mjr_figure keeps the
    // [0, 1] range it was given).
    const double y = UnitToRow(f, p.y_axis.ToUnit(p.y_ticks[i]));
    const int w = text.width(p.y_labels[i]);
    const int row = ch + ch / 4;
    mjr_label({f.xaxispixel[0] - ch / 3 - w, static_cast<int>(std::lround(y)) - row / 2, w, row},
              mjFONT_NORMAL, p.y_labels[i].c_str(), 0, 0, 0, 0, f.textrgb[0], f.textrgb[1],
              f.textrgb[2], con);
  }
}

void TelemetryPlots::Draw(mjrRect area, const mjrContext* con) {
  const TextMetrics text = TextMetrics::FromContext(con);
  Prepare(area, text);
  const std::vector<PanelBoxes> boxes = Layout(area, text);
  const float line_px = 1.5f * std::max(50, con->fontScale) / 100.f;
  for (int p = 0; p < num_panels(); ++p) {
    if (boxes[p].figure.height <= 0) continue;
    Panel& panel = panels_[p];
    panel.fig->linewidth = line_px;
    panel.dash->linewidth = line_px;
    panel.fig->gridwidth = std::max(1.f, line_px / 2);
    panel.dash->gridwidth = panel.fig->gridwidth;
    DrawLegend(panel, boxes[p].legend, con, text, line_px);
    // Bands under the lines: the pane and grid first (no lines), the bands, then the same
    // figure again with transparent backgrounds for its lines.
    mjvFigure* fig = panel.fig.get();
    int linepnt[mjMAXLINE];
    std::memcpy(linepnt, fig->linepnt, sizeof(linepnt));
    std::fill(fig->linepnt, fig->linepnt + mjMAXLINE, 0);
    mjr_figure(boxes[p].figure, fig, con);
    DrawBands(panel, con);
    std::memcpy(fig->linepnt, linepnt, sizeof(linepnt));
    const float figure_alpha = fig->figurergba[3], pane_alpha = fig->panergba[3];
    fig->figurergba[3] = fig->panergba[3] = 0.f;
    mjr_figure(boxes[p].figure, fig, con);
    fig->figurergba[3] = figure_alpha;
    fig->panergba[3] = pane_alpha;
    DrawYLabels(panel, con, text);
    mjr_figure(boxes[p].figure, panel.dash.get(), con);
  }
}

}  // namespace recruit::render
