// CameraSpec: which camera a render uses. With nothing set, the model's camera named "render" if
// it has one, else the free camera. Otherwise either a camera the model names (<camera name=..>),
// or MuJoCo's free camera given by azimuth, elevation, distance and look-at point; any free
// parameter left unset takes mjv_defaultFreeCamera's value for the model (look at the model's
// centre from a distance that frames its extent).
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <optional>
#include <string>

#include "common/result.h"

namespace recruit::render {

struct CameraSpec {
  std::string name;                             // a model camera; empty = free camera
  std::optional<double> azimuth;                // deg, about +z, MuJoCo's convention
  std::optional<double> elevation;              // deg, in [-90, 90]; negative looks down
  std::optional<double> distance;               // m, > 0, from the look-at point
  std::optional<std::array<double, 3>> lookat;  // m, world frame

  bool has_free_parameters() const { return azimuth || elevation || distance || lookat; }
};

// With no camera options, a model camera of this name is used if the model has one.
inline constexpr const char* kDefaultCameraName = "render";

// Names of the model's cameras, comma separated ("" when it has none).
std::string ListCameras(const mjModel* m);

// Checks the spec against the model and returns the mjvCamera to render with. Errors name the
// field and what is allowed (an unknown camera name lists the model's cameras).
Result<mjvCamera> ResolveCamera(const mjModel* m, const CameraSpec& spec);

}  // namespace recruit::render
