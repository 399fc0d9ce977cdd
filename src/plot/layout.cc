#include "plot/layout.h"

#include <algorithm>
#include <cmath>

namespace recruit::plot {

bool Rect::Contains(double px, double py) const {
  return px >= x && px <= right() && py >= y && py <= bottom();
}

bool Rect::Intersects(const Rect& o) const {
  return x < o.right() && o.x < right() && y < o.bottom() && o.y < bottom();
}

double PanelLayout::XToPx(double v) const {
  return data.x + (v - x_ticks.lo) / (x_ticks.hi - x_ticks.lo) * data.w;
}

double PanelLayout::YToPx(double v) const {
  return data.bottom() - (v - y_ticks.lo) / (y_ticks.hi - y_ticks.lo) * data.h;
}

double EstimateTextWidth(const std::string& text, double font_px) {
  size_t chars = 0;  // UTF-8: count code points, not bytes
  for (unsigned char c : text) chars += (c & 0xC0) != 0x80;
  return 0.62 * font_px * static_cast<double>(chars);
}

double FontPxFor(double width, double height) {
  return std::max(kMinFontPx, 0.017 * std::min(width, 1.6 * height));
}

namespace {

std::vector<LegendItem> LegendItemsOf(const Axes& a) {
  std::vector<LegendItem> items;
  for (size_t i = 0; i < a.series.size(); ++i) {
    if (!a.series[i].label.empty()) items.push_back({a.series[i].label, false, int(i)});
  }
  for (size_t i = 0; i < a.bands.size(); ++i) {
    if (!a.bands[i].label.empty()) items.push_back({a.bands[i].label, true, int(i)});
  }
  return items;
}

// Width of the widest legend entry: swatch, gap, label.
double LegendEntryWidth(const std::vector<LegendItem>& items, const FigureLayout& f,
                        const TextWidth& tw) {
  double w = 0;
  for (const auto& it : items) w = std::max(w, tw(it.label, f.font_px));
  return f.swatch_px + f.pad + w;
}

}  // namespace

std::vector<std::string> WrapAtCommas(const std::string& text, double max_w, double px,
                                      const TextWidth& tw) {
  std::vector<std::string> lines;
  size_t start = 0;
  while (start < text.size()) {
    // Take the longest run of ", "-separated parts that fits (at least one part).
    size_t end = text.find(", ", start), best = end;
    while (end != std::string::npos) {
      if (tw(text.substr(start, end - start), px) > max_w) break;
      best = end;
      end = text.find(", ", end + 2);
    }
    if (end == std::string::npos && tw(text.substr(start), px) <= max_w) best = end;
    if (best == std::string::npos) {
      lines.push_back(text.substr(start));
      break;
    }
    lines.push_back(text.substr(start, best - start + 1));  // keeps the comma
    start = best + 2;
  }
  return lines;
}

namespace {

double RowHeight(const FigureLayout& f) { return 1.4 * f.font_px; }

// The y range of a panel: fixed, or from the data (0..1 when there is none). When every series
// is >= 0 (counts, forces), a band (an estimate's +- 2 sd) does not take the axis below zero:
// the axis starts at 0 and the band is clipped there.
Range YRangeOf(const Axes& a) {
  if (a.y_range) return *a.y_range;
  std::optional<Range> r = DataRangeY(a);
  if (!r) return Range{0, 1};
  bool any = false, nonnegative = true;
  for (const Series& s : a.series) {
    for (double y : s.y) {
      if (!std::isfinite(y)) continue;
      any = true;
      nonnegative = nonnegative && y >= 0;
    }
  }
  if (any && nonnegative && r->lo < 0) r->lo = 0;
  return *r;
}

TickSet YTicksFor(const Axes& a, double data_h, double font_px) {
  const int target = std::clamp(static_cast<int>(data_h / (2.5 * font_px)), 1, 8);
  const Range r = YRangeOf(a);
  return MakeTicks(r.lo, r.hi, target);
}

// X ticks: among the tick sets whose labels fit side by side (gap >= 1.5 em), the one that
// best trades how far the axis runs past the data (a time axis to 150 s for 110 s of data
// wastes a quarter of the plot) against a tick count near one per 6 em.
TickSet XTicksFor(const Range& r, double data_w, double font_px, const TextWidth& tw) {
  const double wanted = std::max(1.0, data_w / (6 * font_px));
  const int most = std::clamp(static_cast<int>(data_w / (3.5 * font_px)), 1, 20);
  TickSet best;
  double best_score = 1e300;
  for (int target = most; target >= 1; --target) {
    TickSet t = MakeTicks(r.lo, r.hi, target);
    double widest = 0;
    for (const auto& l : t.labels) widest = std::max(widest, tw(l, font_px));
    const double intervals = static_cast<double>(t.values.size() - 1);
    const bool fits = widest + 1.5 * font_px <= data_w / intervals;
    const double span = std::max(r.hi - r.lo, 1e-300);
    const double score = ((t.hi - t.lo) - span) / span + 0.05 * std::abs(intervals - wanted);
    if ((fits && score < best_score) || (target == 1 && best.values.empty())) {
      best = std::move(t);
      best_score = score;
    }
  }
  return best;
}

// Places the legend entries of one panel in `box` (flowing into rows of `cols` columns).
void PlaceLegend(PanelLayout& p, const FigureLayout& f, double col_w, int cols) {
  const double row_h = RowHeight(f);
  for (size_t i = 0; i < p.legend_items.size(); ++i) {
    const int row = static_cast<int>(i) / cols, col = static_cast<int>(i) % cols;
    p.legend_items[i].x = p.legend.x + f.pad + col * (col_w + 2 * f.pad);
    p.legend_items[i].y = p.legend.y + f.pad + (row + 0.5) * row_h;
  }
}

double LegendHeight(size_t items, int cols, const FigureLayout& f) {
  if (items == 0) return 0;
  const size_t rows = (items + cols - 1) / cols;
  return rows * RowHeight(f) + 2 * f.pad;
}

}  // namespace

namespace {

FigureLayout LayoutWith(const Figure& figure, double width, double height, const TextWidth& tw,
                        bool force_below) {
  FigureLayout f;
  f.width = width, f.height = height;
  f.font_px = FontPxFor(width, height);
  f.pad = 0.5 * f.font_px;
  f.line_px = std::max(1.0, f.font_px / 7);
  f.swatch_px = 2.2 * f.font_px;
  // The title shrinks (not below the minimum font), then wraps at ", ", rather than run off
  // the canvas.
  f.title_px = 1.15 * f.font_px;
  if (!figure.title.empty()) {
    const double w = tw(figure.title, f.title_px);
    if (w > 0.96 * width) f.title_px = std::max(kMinFontPx, f.title_px * 0.96 * width / w);
    f.title_lines = WrapAtCommas(figure.title, 0.96 * width, f.title_px, tw);
  }
  const size_t n = figure.panels.size();
  if (n == 0) return f;

  std::vector<std::vector<LegendItem>> items(n);
  double entry_w = 0;
  for (size_t i = 0; i < n; ++i) {
    items[i] = LegendItemsOf(figure.panels[i]);
    if (!items[i].empty()) entry_w = std::max(entry_w, LegendEntryWidth(items[i], f, tw));
  }
  const double legend_w = entry_w > 0 ? entry_w + 2 * f.pad : 0;
  // Legend on the right while the data keeps >= 55 % of the width; else below each panel
  // (the left margin is about 6.5 em).
  f.legend_below = force_below || legend_w > 0.45 * width - 6.5 * f.font_px;
  const int cols_below = std::max(1, static_cast<int>((width - 2 * f.pad) / (entry_w + 2 * f.pad)));

  // Room above the first panel for the title, or for half of the top y tick label.
  const double top =
      f.title_lines.empty() ? f.font_px : (1.25 * f.title_lines.size() + 0.75) * f.title_px;
  const double x_tick_h = 1.6 * f.font_px, x_label_h = 1.5 * f.font_px;
  const double panel_h = (height - top - f.pad) / n;

  // Vertical placement first (the y ticks depend on the data heights), then the left margin
  // from the widest y tick label of all panels, so the panels share one x axis alignment.
  f.panels.resize(n);
  double widest_y_label = 0;
  for (size_t i = 0; i < n; ++i) {
    PanelLayout& p = f.panels[i];
    p.legend_items = items[i];
    p.draw_x_label = i + 1 == n || figure.panels[i].x_label != figure.panels[i + 1].x_label;
    const double below = x_tick_h + (p.draw_x_label ? x_label_h : 0) +
                         (f.legend_below ? LegendHeight(items[i].size(), cols_below, f) : 0);
    const double gap = i == 0 ? 0 : f.font_px;  // keeps tick labels of stacked panels apart
    p.data.y = top + i * panel_h + gap;
    p.data.h = std::max(1.0, panel_h - below - gap);
    p.y_ticks = YTicksFor(figure.panels[i], p.data.h, f.font_px);
    for (const auto& l : p.y_ticks.labels)
      widest_y_label = std::max(widest_y_label, tw(l, f.font_px));
  }
  const double left = f.pad + 1.3 * f.font_px + f.pad + widest_y_label + f.pad;
  const double right = f.legend_below ? 2 * f.pad : legend_w + 3 * f.pad;
  for (size_t i = 0; i < n; ++i) {
    PanelLayout& p = f.panels[i];
    p.data.x = left;
    p.data.w = std::max(1.0, width - left - right);
    const Range xr = DataRangeX(figure.panels[i]).value_or(Range{0, 1});
    p.x_ticks = XTicksFor(xr, p.data.w, f.font_px, tw);
    if (p.legend_items.empty()) continue;
    if (f.legend_below) {
      const double y = p.data.bottom() + x_tick_h + (p.draw_x_label ? x_label_h : 0);
      const double used = static_cast<double>(std::min<size_t>(items[i].size(), cols_below));
      p.legend = {f.pad, y, std::min(width - 2 * f.pad, used * (entry_w + 2 * f.pad)),
                  LegendHeight(items[i].size(), cols_below, f)};
      PlaceLegend(p, f, entry_w, cols_below);
    } else {
      p.legend = {p.data.right() + 2 * f.pad, p.data.y, legend_w,
                  LegendHeight(items[i].size(), 1, f)};
      PlaceLegend(p, f, entry_w, 1);
    }
  }
  return f;
}

// A legend to the right taller than its panel's slot would run into the next panel's legend or
// off the canvas.
bool RightLegendsFit(const FigureLayout& f) {
  for (size_t i = 0; i < f.panels.size(); ++i) {
    const double limit = i + 1 < f.panels.size() ? f.panels[i + 1].data.y : f.height;
    if (f.panels[i].legend.bottom() > limit) return false;
  }
  return true;
}

}  // namespace

FigureLayout ComputeLayout(const Figure& figure, double width, double height, const TextWidth& tw) {
  FigureLayout f = LayoutWith(figure, width, height, tw, false);
  if (!f.legend_below && !RightLegendsFit(f)) f = LayoutWith(figure, width, height, tw, true);
  return f;
}

}  // namespace recruit::plot
