#include "render/tendon_heat.h"

#include <algorithm>
#include <cmath>

namespace recruit::render {

std::array<float, 4> HeatColour(double heat) {
  const float h = std::isfinite(heat) ? static_cast<float>(std::clamp(heat, 0.0, 1.0)) : 0.f;
  constexpr std::array<float, 3> kCold = {0.10f, 0.30f, 1.00f};
  constexpr std::array<float, 3> kHot = {1.00f, 0.15f, 0.05f};
  return {kCold[0] + h * (kHot[0] - kCold[0]), kCold[1] + h * (kHot[1] - kCold[1]),
          kCold[2] + h * (kHot[2] - kCold[2]), 1.f};
}

int ColourTendonsByHeat(const mjModel* m, const TelemetrySample& sample, mjvScene* scene) {
  int count = 0;
  for (const BundleTelemetry& b : sample.bundles) {
    if (b.tendon_id < 0 || b.tendon_id >= m->ntendon) continue;
    const std::array<float, 4> rgba = HeatColour(b.heat);
    for (int g = 0; g < scene->ngeom; ++g) {
      mjvGeom& geom = scene->geoms[g];
      if (geom.objtype == mjOBJ_TENDON && geom.objid == b.tendon_id) {
        std::copy(rgba.begin(), rgba.end(), geom.rgba);
        ++count;
      }
    }
  }
  return count;
}

int WidenTendons(const mjModel* m, const TelemetrySample& sample, double min_width,
                 mjvScene* scene) {
  int count = 0;
  const float w = static_cast<float>(min_width);
  for (const BundleTelemetry& b : sample.bundles) {
    if (b.tendon_id < 0 || b.tendon_id >= m->ntendon) continue;
    for (int g = 0; g < scene->ngeom; ++g) {
      mjvGeom& geom = scene->geoms[g];
      if (geom.objtype != mjOBJ_TENDON || geom.objid != b.tendon_id) continue;
      // Connectors (capsule/cylinder segments) carry the radius in size[0] and size[1]; the
      // spheres at wrap points in all three.
      const int n = geom.type == mjGEOM_SPHERE ? 3 : 2;
      for (int k = 0; k < n; ++k) geom.size[k] = std::max(geom.size[k], w);
      ++count;
    }
  }
  return count;
}

}  // namespace recruit::render
