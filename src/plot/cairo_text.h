// Text in the figures' font on a cairo surface, shared by the run figures (render.cc) and the
// sweep's stability map.
#pragma once

#include <cairo.h>

#include <string>

namespace recruit::plot {

// Selects the figures' font (DejaVu Sans) at `px` pixels.
void SetFigureFont(cairo_t* cr, double px);

// Draws `text` with its anchor at (x, y): ax = 0 left, 0.5 centre, 1 right; y is the text's
// vertical centre (ascent of digits). Colour r, g, b, a (default: the figures' ink).
void DrawText(cairo_t* cr, const std::string& text, double x, double y, double px, double ax,
              double r = 0.15, double g = 0.15, double b = 0.15, double a = 1);

}  // namespace recruit::plot
