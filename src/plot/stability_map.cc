#include "plot/stability_map.h"

#include <cairo-svg.h>
#include <cairo.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <set>
#include <sstream>

#include "common/short_text.h"
#include "plot/cairo_text.h"
#include "plot/run_data.h"

namespace recruit::plot {
namespace {

cairo_status_t Append(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

void Draw(cairo_t* cr, const std::vector<StabilityPanel>& panels, const std::string& title,
          int width, int height) {
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  const double px = std::clamp(height / 28.0, 9.0, 40.0);  // font size
  DrawText(cr, title, width / 2.0, 1.2 * px, 1.1 * px, 0.5);
  const int n = static_cast<int>(panels.size());
  const double key_w = 6 * px;  // colour key on the right
  const double panel_w = (width - key_w) / std::max(1, n);
  const double top = 3.8 * px, bottom = height - 3.2 * px;
  for (int p = 0; p < n; ++p) {
    const StabilityPanel& panel = panels[p];
    std::set<double> dts, lambdas;
    for (const auto& c : panel.cells) dts.insert(c.dT), lambdas.insert(c.lambda);
    const std::vector<double> xs(dts.begin(), dts.end()), ys(lambdas.begin(), lambdas.end());
    const double left = p * panel_w + 4.5 * px, right = (p + 1) * panel_w - px;
    DrawText(cr, panel.estimator, (left + right) / 2, top - 0.9 * px, px, 0.5);
    const double cw = (right - left) / std::max<size_t>(1, xs.size());
    const double ch = (bottom - top) / std::max<size_t>(1, ys.size());
    for (const auto& c : panel.cells) {
      const size_t i = std::lower_bound(xs.begin(), xs.end(), c.dT) - xs.begin();
      const size_t j = std::lower_bound(ys.begin(), ys.end(), c.lambda) - ys.begin();
      const double x = left + i * cw, y = bottom - (j + 1) * ch;
      const Color col = OvershootColor(c.overshoot_percent);
      cairo_set_source_rgb(cr, col.r, col.g, col.b);
      cairo_rectangle(cr, x + 1, y + 1, cw - 2, ch - 2);
      cairo_fill(cr);
      if (c.meets) {  // the ring: meets the sweep's criterion
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_set_line_width(cr, std::max(2.0, px / 5));
        cairo_arc(cr, x + cw / 2, y + ch / 2, 0.42 * std::min(cw, ch), 0, 2 * M_PI);
        cairo_stroke(cr);
      }
      DrawText(cr, fmt::format("{:.0f}", c.overshoot_percent), x + cw / 2, y + ch / 2, px, 0.5);
    }
    for (size_t i = 0; i < xs.size(); ++i) {
      DrawText(cr, fmt::format("{:g}", xs[i]), left + (i + 0.5) * cw, bottom + 0.9 * px, px, 0.5);
    }
    DrawText(cr, "dT (s)", (left + right) / 2, bottom + 2.3 * px, px, 0.5);
    for (size_t j = 0; j < ys.size(); ++j) {
      DrawText(cr, fmt::format("{:g}", ys[j]), left - 0.4 * px, bottom - (j + 0.5) * ch, px, 1);
    }
    cairo_save(cr);
    cairo_translate(cr, p * panel_w + 1.0 * px, (top + bottom) / 2);
    cairo_rotate(cr, -M_PI / 2);
    DrawText(cr, "lambda", 0, 0, px, 0.5);
    cairo_restore(cr);
  }
  // Key: the colour ramp 0..50 % with ticks.
  const double kx = width - key_w + 1.2 * px, kw = 1.2 * px;
  for (int k = 0; k < 100; ++k) {
    const Color c = OvershootColor(50.0 * (k + 0.5) / 100);
    cairo_set_source_rgb(cr, c.r, c.g, c.b);
    const double y0 = bottom - (bottom - top) * (k + 1) / 100.0;
    cairo_rectangle(cr, kx, y0, kw, (bottom - top) / 100.0 + 0.5);
    cairo_fill(cr);
  }
  for (int v : {0, 10, 20, 30, 40, 50}) {
    DrawText(cr, v == 50 ? ">=50" : std::to_string(v), kx + kw + 0.3 * px,
             bottom - (bottom - top) * v / 50.0, 0.85 * px, 0);
  }
  DrawText(cr, "overshoot (%)", kx + kw / 2, top - 0.9 * px, 0.85 * px, 0.5);
}

}  // namespace

Color OvershootColor(double percent) {
  const double v = std::isfinite(percent) ? std::clamp(percent, 0.0, 50.0) : 50.0;
  const Color green{0.13, 0.55, 0.13}, yellow{1.0, 0.9, 0.1}, red{0.85, 0.1, 0.1};
  const auto mix = [](const Color& a, const Color& b, double t) {
    return Color{a.r + t * (b.r - a.r), a.g + t * (b.g - a.g), a.b + t * (b.b - a.b), 1};
  };
  return v <= 10 ? mix(green, yellow, v / 10) : mix(yellow, red, (v - 10) / 40);
}

Result<std::vector<StabilityPanel>> ParseStabilityDat(const std::string& text,
                                                      const std::string& path) {
  std::vector<StabilityPanel> panels;
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    const std::string tag = "# estimator ";
    if (line.rfind(tag, 0) == 0) {
      panels.push_back({line.substr(tag.size()), {}});
      continue;
    }
    if (line[0] == '#') continue;
    if (panels.empty()) {
      return Error{
          fmt::format("{} line {}: data before any '# estimator NAME' line", path, line_no)};
    }
    std::istringstream row(line);
    StabilityCell c;
    int meets = -1;
    std::string extra;
    if (!(row >> c.dT >> c.lambda >> c.overshoot_percent >> meets) || (row >> extra) ||
        (meets != 0 && meets != 1) || !(c.dT > 0) || !std::isfinite(c.lambda)) {
      return Error{fmt::format(
          "{} line {}: '{}' is not 'dT lambda overshoot_percent meets(0/1)' with dT > 0", path,
          line_no, ShortText(line))};
    }
    c.meets = meets == 1;
    panels.back().cells.push_back(c);
  }
  panels.erase(std::remove_if(panels.begin(), panels.end(),
                              [](const StabilityPanel& p) { return p.cells.empty(); }),
               panels.end());
  if (panels.empty()) return Error{path + ": no cells (expected sweep's stability.dat)"};
  return panels;
}

Result<std::string> RenderStabilityMap(const std::vector<StabilityPanel>& panels,
                                       const std::string& title, int width, int height,
                                       Format format) {
  std::string bytes;
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface(
      format == Format::kPng ? cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height)
                             : cairo_svg_surface_create_for_stream(Append, &bytes, width, height),
      cairo_surface_destroy);
  if (format == Format::kSvg) cairo_svg_surface_set_document_unit(surface.get(), CAIRO_SVG_UNIT_PX);
  {
    std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr(cairo_create(surface.get()),
                                                          cairo_destroy);
    Draw(cr.get(), panels, title, width, height);
    if (auto st = cairo_status(cr.get()); st != CAIRO_STATUS_SUCCESS) {
      return Error{std::string("cairo: ") + cairo_status_to_string(st)};
    }
  }
  cairo_status_t st;
  if (format == Format::kPng) {
    st = cairo_surface_write_to_png_stream(surface.get(), Append, &bytes);
  } else {
    cairo_surface_finish(surface.get());
    st = cairo_surface_status(surface.get());
  }
  if (st != CAIRO_STATUS_SUCCESS) return Error{std::string("cairo: ") + cairo_status_to_string(st)};
  return bytes;
}

}  // namespace recruit::plot
