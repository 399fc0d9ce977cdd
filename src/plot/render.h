// Draws a Figure with cairo. PNG and SVG come from the same drawing code (DrawFigure); only the
// surface differs. The result is the file's bytes, so callers write it atomically.
#pragma once

#include <string>

#include "common/result.h"
#include "plot/figure.h"
#include "plot/layout.h"

namespace recruit::plot {

enum class Format { kPng, kSvg };

// Renders `figure` on a width x height canvas (pixels; SVG user units). Errors name cairo's
// status.
Result<std::string> RenderFigure(const Figure& figure, int width, int height, Format format);

// The layout RenderFigure uses: ComputeLayout with cairo's text measure (the same font).
FigureLayout LayoutWithCairoText(const Figure& figure, int width, int height);

}  // namespace recruit::plot
