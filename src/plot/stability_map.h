// The stability map of a `recruit sweep` (`recruit plot --stability-map DIR/stability.dat`): one
// panel per estimator, a cell per (dT, lambda) coloured by the mean step overshoot (green 0 %,
// yellow 10 %, red >= 50 %) with its value, a black ring where the sweep's criterion is met.
// What sweep's stability.gp draws with gnuplot, made by the program. PNG or SVG bytes.
#pragma once

#include <string>
#include <vector>

#include "common/result.h"
#include "plot/figure.h"
#include "plot/render.h"

namespace recruit::plot {

struct StabilityCell {
  double dT = 0, lambda = 0, overshoot_percent = 0;
  bool meets = false;
};

struct StabilityPanel {
  std::string estimator;
  std::vector<StabilityCell> cells;
};

// Parses sweep's stability.dat: blocks headed "# estimator NAME", rows "dT lambda overshoot%
// meets(0/1)". Errors name the file, the line and the value.
Result<std::vector<StabilityPanel>> ParseStabilityDat(const std::string& text,
                                                      const std::string& path);

// The overshoot colour: green at 0 %, yellow at 10 %, red at >= 50 %, linear between.
Color OvershootColor(double percent);

Result<std::string> RenderStabilityMap(const std::vector<StabilityPanel>& panels,
                                       const std::string& title, int width, int height,
                                       Format format);

}  // namespace recruit::plot
