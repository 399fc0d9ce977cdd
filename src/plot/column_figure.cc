#include "plot/column_figure.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <sstream>

#include "common/short_text.h"

namespace recruit::plot {
namespace {

// Distinct, colour-blind-safe hues (Okabe-Ito), in series order within a panel.
constexpr Color kPalette[] = {{0.84, 0.37, 0.0}, {0.0, 0.45, 0.70},  {0.0, 0.62, 0.45},
                              {0.8, 0.47, 0.65}, {0.34, 0.71, 0.91}, {0.9, 0.62, 0.0}};

std::string Trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t") - a + 1);
}

std::string Columns(const RunCsv& t) {
  std::string list;
  for (const auto& n : t.names) list += (list.empty() ? "" : ", ") + n;
  return list;
}

}  // namespace

Result<PanelSpec> ParsePanelSpec(const std::string& spec) {
  const size_t eq = spec.rfind('=');
  if (eq == std::string::npos || Trim(spec.substr(0, eq)).empty()) {
    return Error{fmt::format(
        "--panel '{}': expected LABEL=COLUMN[*SCALE][,COLUMN...], e.g. 'force (N)=tension'",
        ShortText(spec))};
  }
  PanelSpec p;
  p.y_label = Trim(spec.substr(0, eq));
  std::istringstream in(spec.substr(eq + 1));
  std::string item;
  while (std::getline(in, item, ',')) {
    ColumnRef c;
    const size_t star = item.find('*');
    c.column = Trim(item.substr(0, star));
    if (star != std::string::npos) {
      const std::string num = Trim(item.substr(star + 1));
      char* end = nullptr;
      c.scale = std::strtod(num.c_str(), &end);
      if (num.empty() || *end != '\0' || !std::isfinite(c.scale) || c.scale == 0) {
        return Error{fmt::format("--panel '{}': scale '{}' is not a finite non-zero number",
                                 ShortText(spec), ShortText(num))};
      }
    }
    if (c.column.empty()) {
      return Error{fmt::format("--panel '{}': empty column name", ShortText(spec))};
    }
    p.columns.push_back(c);
  }
  if (p.columns.empty()) {
    return Error{fmt::format("--panel '{}': no column after '='", ShortText(spec))};
  }
  return p;
}

Result<Figure> MakeColumnFigure(const RunCsv& table, const std::string& x,
                                const std::string& x_label, const std::vector<PanelSpec>& panels,
                                const std::string& title) {
  const std::vector<double>* xs = table.Find(x);
  if (!xs) {
    return Error{fmt::format("{}: no column '{}' for x (columns: {})", table.path, ShortText(x),
                             Columns(table))};
  }
  Figure fig;
  fig.title = title;
  for (const PanelSpec& spec : panels) {
    Axes axes;
    axes.y_label = spec.y_label;
    axes.x_label = x_label;
    int k = 0;
    for (const ColumnRef& c : spec.columns) {
      const std::vector<double>* ys = table.Find(c.column);
      if (!ys) {
        return Error{fmt::format("{}: no column '{}' (columns: {})", table.path,
                                 ShortText(c.column), Columns(table))};
      }
      Series s;
      s.label = c.scale == 1 ? c.column : fmt::format("{} x {:g}", c.column, c.scale);
      s.x = *xs;
      s.y = *ys;
      for (double& v : s.y) v *= c.scale;
      s.color = kPalette[k % (sizeof(kPalette) / sizeof(kPalette[0]))];
      s.width = k == 0 ? 1.6 : 1.2;
      s.style = k < 2 ? LineStyle::kSolid : k < 4 ? LineStyle::kDashed : LineStyle::kDotted;
      axes.series.push_back(std::move(s));
      ++k;
    }
    fig.panels.push_back(std::move(axes));
  }
  return fig;
}

}  // namespace recruit::plot
