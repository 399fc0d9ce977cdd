#include "plot/render.h"

#include <cairo-svg.h>
#include <cairo.h>

#include <cmath>
#include <memory>

#include "plot/cairo_text.h"
#include "plot/decimate.h"

namespace recruit::plot {
namespace {

const Color kInk{0.15, 0.15, 0.15}, kGrid{0.88, 0.88, 0.88}, kFrame{0.35, 0.35, 0.35};

using CairoPtr = std::unique_ptr<cairo_t, decltype(&cairo_destroy)>;
using SurfacePtr = std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)>;

void SetColor(cairo_t* cr, const Color& c) { cairo_set_source_rgba(cr, c.r, c.g, c.b, c.a); }

double CairoTextWidth(cairo_t* cr, const std::string& text, double px) {
  SetFigureFont(cr, px);
  cairo_text_extents_t e;
  cairo_text_extents(cr, text.c_str(), &e);
  return e.x_advance;
}

void Text(cairo_t* cr, const std::string& text, double x, double y, double px, double ax,
          const Color& c = kInk) {
  DrawText(cr, text, x, y, px, ax, c.r, c.g, c.b, c.a);
}

void SetDash(cairo_t* cr, LineStyle style, double line_px) {
  const double dash[] = {4 * line_px, 3 * line_px}, dot[] = {line_px, 2 * line_px};
  if (style == LineStyle::kDashed)
    cairo_set_dash(cr, dash, 2, 0);
  else if (style == LineStyle::kDotted)
    cairo_set_dash(cr, dot, 2, 0);
  else
    cairo_set_dash(cr, nullptr, 0, 0);
}

void DrawGridAndFrame(cairo_t* cr, const PanelLayout& p, const FigureLayout& f) {
  cairo_set_line_width(cr, std::max(1.0, 0.6 * f.line_px));
  SetColor(cr, kGrid);
  for (double v : p.x_ticks.values) {
    cairo_move_to(cr, p.XToPx(v), p.data.y);
    cairo_line_to(cr, p.XToPx(v), p.data.bottom());
  }
  for (double v : p.y_ticks.values) {
    cairo_move_to(cr, p.data.x, p.YToPx(v));
    cairo_line_to(cr, p.data.right(), p.YToPx(v));
  }
  cairo_stroke(cr);
  SetColor(cr, kFrame);
  cairo_rectangle(cr, p.data.x, p.data.y, p.data.w, p.data.h);
  cairo_stroke(cr);
}

void DrawTickLabels(cairo_t* cr, const PanelLayout& p, const FigureLayout& f) {
  for (size_t i = 0; i < p.x_ticks.values.size(); ++i) {
    Text(cr, p.x_ticks.labels[i], p.XToPx(p.x_ticks.values[i]), p.data.bottom() + f.font_px,
         f.font_px, 0.5);
  }
  for (size_t i = 0; i < p.y_ticks.values.size(); ++i) {
    Text(cr, p.y_ticks.labels[i], p.data.x - f.pad, p.YToPx(p.y_ticks.values[i]), f.font_px, 1);
  }
}

void DrawAxisLabels(cairo_t* cr, const Axes& a, const PanelLayout& p, const FigureLayout& f) {
  if (p.draw_x_label) {
    Text(cr, a.x_label, p.data.x + 0.5 * p.data.w, p.data.bottom() + 2.4 * f.font_px, f.font_px,
         0.5);
  }
  cairo_save(cr);
  cairo_translate(cr, f.pad + 0.65 * f.font_px, p.data.y + 0.5 * p.data.h);
  cairo_rotate(cr, -M_PI / 2);
  Text(cr, a.y_label, 0, 0, f.font_px, 0.5);
  cairo_restore(cr);
}

// Fills each run of rows where both edges are finite as one polygon.
void DrawBand(cairo_t* cr, const Band& b, const PanelLayout& p, int buckets) {
  const XBand d = DecimateEnvelope(b.x, b.lo, b.hi, buckets);
  SetColor(cr, b.color);
  size_t i = 0;
  while (i < d.x.size()) {
    while (i < d.x.size() && !(std::isfinite(d.lo[i]) && std::isfinite(d.hi[i]))) ++i;
    size_t j = i;
    while (j < d.x.size() && std::isfinite(d.lo[j]) && std::isfinite(d.hi[j])) ++j;
    if (j > i) {
      for (size_t k = i; k < j; ++k) cairo_line_to(cr, p.XToPx(d.x[k]), p.YToPx(d.hi[k]));
      for (size_t k = j; k-- > i;) cairo_line_to(cr, p.XToPx(d.x[k]), p.YToPx(d.lo[k]));
      cairo_close_path(cr);
      cairo_fill(cr);
    }
    i = j;
  }
}

void DrawSeries(cairo_t* cr, const Series& s, const PanelLayout& p, const FigureLayout& f,
                int buckets) {
  const XY d = DecimateMinMax(s.x, s.y, buckets);
  bool pen_down = false;
  for (size_t i = 0; i < d.x.size(); ++i) {
    if (!std::isfinite(d.y[i]) || !std::isfinite(d.x[i])) {
      pen_down = false;
      continue;
    }
    const double px = p.XToPx(d.x[i]), py = p.YToPx(d.y[i]);
    pen_down ? cairo_line_to(cr, px, py) : cairo_move_to(cr, px, py);
    pen_down = true;
  }
  SetColor(cr, s.color);
  cairo_set_line_width(cr, s.width * f.line_px);
  SetDash(cr, s.style, s.width * f.line_px);
  cairo_stroke(cr);
  SetDash(cr, LineStyle::kSolid, 1);
}

void DrawData(cairo_t* cr, const Axes& a, const PanelLayout& p, const FigureLayout& f) {
  cairo_save(cr);
  cairo_rectangle(cr, p.data.x, p.data.y, p.data.w, p.data.h);
  cairo_clip(cr);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  const int buckets = std::max(1, static_cast<int>(p.data.w));
  for (const Band& b : a.bands) DrawBand(cr, b, p, buckets);
  for (const Series& s : a.series) DrawSeries(cr, s, p, f, buckets);
  cairo_restore(cr);
}

void DrawLegend(cairo_t* cr, const Axes& a, const PanelLayout& p, const FigureLayout& f) {
  if (p.legend_items.empty()) return;
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_rectangle(cr, p.legend.x, p.legend.y, p.legend.w, p.legend.h);
  cairo_fill_preserve(cr);
  SetColor(cr, kGrid);
  cairo_set_line_width(cr, std::max(1.0, 0.6 * f.line_px));
  cairo_stroke(cr);
  for (const LegendItem& it : p.legend_items) {
    if (it.is_band) {
      SetColor(cr, a.bands[it.index].color);
      cairo_rectangle(cr, it.x, it.y - 0.4 * f.font_px, f.swatch_px, 0.8 * f.font_px);
      cairo_fill(cr);
    } else {
      const Series& s = a.series[it.index];
      SetColor(cr, s.color);
      cairo_set_line_width(cr, s.width * f.line_px);
      SetDash(cr, s.style, s.width * f.line_px);
      cairo_move_to(cr, it.x, it.y);
      cairo_line_to(cr, it.x + f.swatch_px, it.y);
      cairo_stroke(cr);
      SetDash(cr, LineStyle::kSolid, 1);
    }
    Text(cr, it.label, it.x + f.swatch_px + f.pad, it.y, f.font_px, 0);
  }
}

void DrawFigure(cairo_t* cr, const Figure& fig, const FigureLayout& f) {
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  for (size_t i = 0; i < f.title_lines.size(); ++i) {
    Text(cr, f.title_lines[i], 0.5 * f.width, (0.9 + 1.25 * i) * f.title_px, f.title_px, 0.5);
  }
  for (size_t i = 0; i < fig.panels.size(); ++i) {
    const PanelLayout& p = f.panels[i];
    DrawGridAndFrame(cr, p, f);
    DrawData(cr, fig.panels[i], p, f);
    DrawTickLabels(cr, p, f);
    DrawAxisLabels(cr, fig.panels[i], p, f);
    DrawLegend(cr, fig.panels[i], p, f);
  }
}

cairo_status_t AppendBytes(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

Result<std::string> Check(cairo_status_t status, std::string bytes) {
  if (status != CAIRO_STATUS_SUCCESS) {
    return Error{std::string("cairo: ") + cairo_status_to_string(status)};
  }
  return bytes;
}

}  // namespace

FigureLayout LayoutWithCairoText(const Figure& figure, int width, int height) {
  SurfacePtr s(cairo_image_surface_create(CAIRO_FORMAT_RGB24, 1, 1), cairo_surface_destroy);
  CairoPtr cr(cairo_create(s.get()), cairo_destroy);
  return ComputeLayout(figure, width, height, [&](const std::string& t, double px) {
    return CairoTextWidth(cr.get(), t, px);
  });
}

Result<std::string> RenderFigure(const Figure& figure, int width, int height, Format format) {
  const FigureLayout layout = LayoutWithCairoText(figure, width, height);
  std::string bytes;
  SurfacePtr surface(format == Format::kPng
                         ? cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height)
                         : cairo_svg_surface_create_for_stream(AppendBytes, &bytes, width, height),
                     cairo_surface_destroy);
  if (auto st = cairo_surface_status(surface.get()); st != CAIRO_STATUS_SUCCESS) {
    return Check(st, "");
  }
  // In pixels, like the PNG (cairo's default unit is pt: 4/3 larger on screen).
  if (format == Format::kSvg) cairo_svg_surface_set_document_unit(surface.get(), CAIRO_SVG_UNIT_PX);
  {
    CairoPtr cr(cairo_create(surface.get()), cairo_destroy);
    DrawFigure(cr.get(), figure, layout);
    if (auto st = cairo_status(cr.get()); st != CAIRO_STATUS_SUCCESS) return Check(st, "");
  }
  cairo_status_t status;
  if (format == Format::kPng) {
    status = cairo_surface_write_to_png_stream(surface.get(), AppendBytes, &bytes);
  } else {
    cairo_surface_finish(surface.get());  // flushes the SVG into `bytes`
    status = cairo_surface_status(surface.get());
  }
  return Check(status, std::move(bytes));
}

}  // namespace recruit::plot
