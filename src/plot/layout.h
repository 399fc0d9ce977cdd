// Layout of a Figure on a canvas of width x height pixels: where each panel's data area, tick
// labels, axis labels and legend go, and the font and line sizes. Pure functions: tests call
// them without drawing.
//
// Rules (docs/plotting.md): the legend sits outside every data area (right of it, or below it
// when the canvas is too narrow), so it never hides data; font and line sizes scale with the
// canvas (font >= kMinFontPx); tick counts follow the room the labels need.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "plot/figure.h"
#include "plot/ticks.h"

namespace recruit::plot {

inline constexpr double kMinFontPx = 10;

struct Rect {
  double x = 0, y = 0, w = 0, h = 0;  // pixels, y down
  double right() const { return x + w; }
  double bottom() const { return y + h; }
  bool Contains(double px, double py) const;
  bool Intersects(const Rect& o) const;  // the interiors overlap
};

struct LegendItem {
  std::string label;
  bool is_band = false;
  int index = 0;        // into the panel's series or bands
  double x = 0, y = 0;  // left end of the swatch, vertical centre of the row
};

struct PanelLayout {
  Rect data;    // the data area (the axis frame)
  Rect legend;  // the legend box (w = h = 0 when there is nothing to list)
  std::vector<LegendItem> legend_items;
  TickSet x_ticks, y_ticks;
  bool draw_x_label = true;
  double XToPx(double x) const;
  double YToPx(double y) const;
};

struct FigureLayout {
  double width = 0, height = 0;
  double font_px = kMinFontPx;  // tick labels, axis labels, legend
  double title_px = kMinFontPx;
  std::vector<std::string> title_lines;  // the title, wrapped to the canvas width
  double line_px = 1;                    // base line width
  double pad = 5;                        // the unit of the gaps between elements
  double swatch_px = 20;                 // length of a legend's line sample
  bool legend_below = false;
  std::vector<PanelLayout> panels;
};

// Width in pixels of `text` at `font_px`. The renderer passes cairo's measure; the default is a
// conservative estimate (0.62 em per character) for tests and for sizing without a surface.
using TextWidth = std::function<double(const std::string& text, double font_px)>;
double EstimateTextWidth(const std::string& text, double font_px);

// The font size for a canvas: grows with min(width, 1.6 height), never below kMinFontPx.
double FontPxFor(double width, double height);

// `text` split after ", " into lines no wider than max_w where possible (a single part wider
// than max_w gets a line of its own).
std::vector<std::string> WrapAtCommas(const std::string& text, double max_w, double px,
                                      const TextWidth& tw);

FigureLayout ComputeLayout(const Figure& figure, double width, double height,
                           const TextWidth& text_width = EstimateTextWidth);

}  // namespace recruit::plot
