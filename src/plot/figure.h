// Figure model of src/plot: panels (axes) stacked vertically, each with series (lines), bands
// (translucent fills between two curves) and a legend. The model is plain data: ComputeLayout
// (layout.h) places it and RenderFigure (render.h) draws it with cairo to PNG or SVG. No MuJoCo.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace recruit::plot {

struct Color {
  double r = 0, g = 0, b = 0, a = 1;
};

enum class LineStyle { kSolid, kDashed, kDotted };

// A polyline through (x[i], y[i]); a non-finite y breaks the line (a gap).
struct Series {
  std::string label;  // legend entry; empty = not listed
  std::vector<double> x, y;
  Color color;
  LineStyle style = LineStyle::kSolid;
  double width = 1;  // in units of the figure's base line width
};

// The area between lo[i] and hi[i]; rows where either is non-finite are left out (a gap).
struct Band {
  std::string label;
  std::vector<double> x, lo, hi;
  Color color;  // its alpha is the fill's opacity
};

struct Range {
  double lo = 0, hi = 0;
};

struct Axes {
  std::string x_label, y_label;  // with units, e.g. "time (s)"
  std::vector<Band> bands;       // drawn first, under the series
  std::vector<Series> series;
  std::optional<Range> y_range;  // fixed y range (e.g. 0..1); otherwise from the data
};

struct Figure {
  std::string title;  // one line above the panels; empty = none
  std::vector<Axes> panels;
};

}  // namespace recruit::plot
