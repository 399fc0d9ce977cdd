// Colouring each SMA bundle's tendon by its heat, so the muscles' state is visible in the scene.
#pragma once

#include <mujoco/mujoco.h>

#include <array>

#include "common/telemetry.h"

namespace recruit::render {

// Linear blend from blue (heat 0: every unit at ambient) to red (heat 1: at the on-state steady
// temperature); heat is clamped to [0, 1], NaN counts as 0. Red rises and blue falls
// monotonically with heat.
std::array<float, 4> HeatColour(double heat);

// Sets the rgba of every scene geom drawn for a bundle's tendon (objtype mjOBJ_TENDON, objid =
// tendon_id) to HeatColour(heat). Call after mjv_updateScene, before mjr_render. Bundles with a
// tendon_id outside [0, ntendon) are skipped. Returns the number of geoms recoloured.
int ColourTendonsByHeat(const mjModel* m, const TelemetrySample& sample, mjvScene* scene);

// Draws each bundle's tendon geoms at least `min_width` (m) thick in the scene only (the model's
// tendon width is for display too, but real bundles are thin). Returns the geoms widened.
int WidenTendons(const mjModel* m, const TelemetrySample& sample, double min_width,
                 mjvScene* scene);

}  // namespace recruit::render
