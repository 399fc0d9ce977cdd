// Shared fixtures for the render tests: a one-hinge arm pulled by a thick spatial tendon, two
// named cameras, and helpers to build synthetic telemetry and project points with a pinhole
// model (an independent check of where MuJoCo draws things).
#pragma once

#include <mujoco/mujoco.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

#include "common/mujoco_load.h"
#include "common/mujoco_ptr.h"
#include "common/telemetry.h"

namespace recruit::render::testing {

inline constexpr const char* kArmXml = R"(
<mujoco model="render-test-arm">
  <compiler autolimits="true"/>
  <option timestep="0.002"/>
  <visual><global offwidth="640" offheight="480"/></visual>
  <worldbody>
    <light pos="0 -1 2" dir="0 0.5 -1" diffuse="0.8 0.8 0.8"/>
    <geom name="floor" type="plane" size="1 1 0.1" rgba="0.8 0.8 0.8 1"/>
    <camera name="front" pos="0 -1.2 0.6" xyaxes="1 0 0 0 0 1"/>
    <camera name="side" pos="1.2 0 0.6" xyaxes="0 1 0 0 0 1"/>
    <site name="anchor" pos="-0.2 -0.05 0.85" size="0.01"/>
    <body name="upper" pos="0 0 0.8">
      <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03" rgba="0.7 0.7 0.7 1"/>
      <body name="fore" pos="0 0 -0.3">
        <joint name="elbow" type="hinge" axis="0 1 0" range="-90 90" damping="0.5"/>
        <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.025" rgba="0.6 0.6 0.6 1"/>
        <site name="insertion" pos="0.12 -0.05 0" size="0.01"/>
      </body>
    </body>
  </worldbody>
  <tendon>
    <spatial name="muscle" width="0.02" rgba="0.5 0.5 0.5 1">
      <site site="anchor"/>
      <site site="insertion"/>
    </spatial>
  </tendon>
  <actuator>
    <motor name="pull" tendon="muscle" gear="-1" ctrlrange="0 20"/>
  </actuator>
</mujoco>
)";

using ::recruit::DataPtr;
using ::recruit::ModelPtr;

inline ModelPtr LoadXml(const char* xml) {
  auto m = ::recruit::LoadModelFromString(xml);
  if (!m.ok()) std::fprintf(stderr, "model error: %s\n", m.error().c_str());
  return m.ok() ? std::move(m).value() : ModelPtr();
}

// A sample with one bundle on tendon 0 at the given heat.
inline TelemetrySample Sample(double time, double heat, int true_on = 10,
                              double estimated_on = 9.5) {
  TelemetrySample s;
  s.time = time;
  s.reference = 12;
  s.measured = 11;
  s.reference_unit = "N";
  BundleTelemetry b;
  b.actuator = "pull";
  b.tendon_id = 0;
  b.heat = heat;
  b.true_on = true_on;
  b.estimated_on = estimated_on;
  b.force = 11;
  s.bundles.push_back(b);
  return s;
}

// Pixel (column, row from the top) where a fixed camera's pinhole projection puts world point
// p, for a width x height frame. MuJoCo cameras look along their -z axis, y up, cam_fovy is the
// vertical field of view.
inline void Project(const mjModel* m, const mjData* d, int cam, const double p[3], int width,
                    int height, double* col, double* row_from_top) {
  const double* c = d->cam_xpos + 3 * cam;
  const double* R = d->cam_xmat + 9 * cam;  // columns: camera x, y, z axes in world
  double v[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
  double xc = R[0] * v[0] + R[3] * v[1] + R[6] * v[2];
  double yc = R[1] * v[0] + R[4] * v[1] + R[7] * v[2];
  double zc = R[2] * v[0] + R[5] * v[1] + R[8] * v[2];
  const double f = 0.5 * height / std::tan(0.5 * m->cam_fovy[cam] * M_PI / 180.0);
  *col = 0.5 * width + f * xc / -zc;
  *row_from_top = 0.5 * height - f * yc / -zc;
}

}  // namespace recruit::render::testing
