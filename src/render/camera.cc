#include "render/camera.h"

#include <cmath>

namespace recruit::render {

std::string ListCameras(const mjModel* m) {
  std::string names;
  for (int i = 0; i < m->ncam; ++i) {
    const char* name = mj_id2name(m, mjOBJ_CAMERA, i);
    if (!names.empty()) names += ", ";
    names += name && *name ? std::string("'") + name + "'" : "#" + std::to_string(i) + " (unnamed)";
  }
  return names;
}

Result<mjvCamera> ResolveCamera(const mjModel* m, const CameraSpec& spec) {
  mjvCamera cam;
  mjv_defaultFreeCamera(m, &cam);
  // Nothing asked for: the model's camera named "render" when it has one (a model's framing of
  // its own motion), else the free camera.
  if (spec.name.empty() && !spec.has_free_parameters()) {
    const int id = mj_name2id(m, mjOBJ_CAMERA, kDefaultCameraName);
    if (id >= 0) {
      cam.type = mjCAMERA_FIXED;
      cam.fixedcamid = id;
      return cam;
    }
  }
  if (!spec.name.empty()) {
    if (spec.has_free_parameters()) {
      return Error{
          "camera: give either a model camera name (--camera) or free-camera parameters "
          "(--azimuth/--elevation/--distance/--lookat), not both"};
    }
    const int id = mj_name2id(m, mjOBJ_CAMERA, spec.name.c_str());
    if (id < 0) {
      const std::string list = ListCameras(m);
      return Error{"camera: the model has no camera named '" + spec.name + "'; " +
                   (list.empty() ? std::string("it defines no cameras, use the free camera "
                                               "(--azimuth, --elevation, --distance, --lookat)")
                                 : "its cameras are " + list)};
    }
    cam.type = mjCAMERA_FIXED;
    cam.fixedcamid = id;
    return cam;
  }
  if (spec.azimuth) {
    if (!std::isfinite(*spec.azimuth))
      return Error{"camera: azimuth must be a finite angle in deg"};
    cam.azimuth = *spec.azimuth;
  }
  if (spec.elevation) {
    if (!std::isfinite(*spec.elevation) || *spec.elevation < -90 || *spec.elevation > 90) {
      return Error{"camera: elevation must be in [-90, 90] deg, got " +
                   std::to_string(*spec.elevation)};
    }
    cam.elevation = *spec.elevation;
  }
  if (spec.distance) {
    if (!std::isfinite(*spec.distance) || *spec.distance <= 0) {
      return Error{"camera: distance must be a positive number of metres, got " +
                   std::to_string(*spec.distance)};
    }
    cam.distance = *spec.distance;
  }
  if (spec.lookat) {
    for (int i = 0; i < 3; ++i) {
      if (!std::isfinite((*spec.lookat)[i]))
        return Error{"camera: lookat must be 3 finite numbers"};
      cam.lookat[i] = (*spec.lookat)[i];
    }
  }
  return cam;
}

}  // namespace recruit::render
