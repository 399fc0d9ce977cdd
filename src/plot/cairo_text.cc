#include "plot/cairo_text.h"

namespace recruit::plot {

void SetFigureFont(cairo_t* cr, double px) {
  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, px);
}

void DrawText(cairo_t* cr, const std::string& text, double x, double y, double px, double ax,
              double r, double g, double b, double a) {
  SetFigureFont(cr, px);
  cairo_text_extents_t e;
  cairo_text_extents(cr, text.c_str(), &e);
  cairo_set_source_rgba(cr, r, g, b, a);
  cairo_move_to(cr, x - ax * e.x_advance, y + 0.36 * px);
  cairo_show_text(cr, text.c_str());
}

}  // namespace recruit::plot
