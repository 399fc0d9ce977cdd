// 2D annotations over the 3D scene: each bundle's name (and temperature) next to its tendon, the
// key of the tendon heat colours, and the title line. Positions come from projecting world points
// with the scene's own camera (the same frustum mjr_render uses).
#pragma once

#include <mujoco/mujoco.h>

#include <optional>
#include <string>
#include <vector>

#include "common/telemetry.h"
#include "render/unit_counts.h"

namespace recruit::render {

struct Pixel {
  double x = 0, y = 0;  // pixels from the viewport's bottom-left corner
};

// Where the world point `p` appears in `viewport` through the scene's averaged camera; nullopt
// when it lies behind the camera.
std::optional<Pixel> ProjectToViewport(const mjvScene& scene, mjrRect viewport, const double p[3]);

// A bundle's label: anchored on its tendon, text to the left or right of it.
struct TendonLabel {
  std::string text;
  Pixel anchor;       // on the tendon, pixels in the scene viewport
  bool left = false;  // the text goes left of the anchor (the leftmost tendon)
};

// One label per bundle whose tendon has a path: anchored at fraction (b + 1) / (n + 1) of the
// tendon's first segment (so labels of parallel tendons are staggered); the tendon drawn
// leftmost gets its text on the left, the others on the right.
// A bundle with unit counts (`counts`, in the sample's order; empty: none) adds "54/60 working".
std::vector<TendonLabel> PlaceTendonLabels(
    const mjModel* m, const mjData* d, const mjvScene& scene, mjrRect viewport,
    const TelemetrySample& sample, const std::vector<std::optional<UnitCounts>>& counts = {});

// Draws the labels (leader line, text on a dark box). `offset` is the viewport's origin in the
// frame.
void DrawTendonLabels(const std::vector<TendonLabel>& labels, mjrRect viewport,
                      const mjrContext* con);

// Draws the heat colour key (a gradient bar with "ambient" and "on-state" at its ends) with its
// top-left corner at (left, top), and returns its height in pixels. `rows` (e.g. each failing
// bundle's "flexor: 54 of 60 working (6 open)", HeatKeyRows) are written under the bar.
int DrawHeatKey(int left, int top, int width, const mjrContext* con,
                const std::vector<std::string>& rows = {});
int HeatKeyHeight(const mjrContext* con, int rows = 0);
// The key's rows for the bundles that have unit counts: "NAME: WorkingText".
std::vector<std::string> HeatKeyRows(const TelemetrySample& sample,
                                     const std::vector<std::optional<UnitCounts>>& counts);

// Text width in pixels in the context's normal font.
int TextWidth(const std::string& s, const mjrContext* con);

}  // namespace recruit::render
