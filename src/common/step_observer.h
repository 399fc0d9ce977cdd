// StepObserver: anything that watches a closed-loop run step by step (the per-step CSV writer,
// the video recorder). The runner calls OnStep after every physics step; an error stops the run.
#pragma once

#include <mujoco/mujoco.h>

#include "common/result.h"
#include "common/telemetry.h"

namespace recruit {

class StepObserver {
 public:
  virtual ~StepObserver() = default;
  virtual Status OnStep(const mjModel* m, const mjData* d, const TelemetrySample& sample) = 0;
  // Called once when the run ends normally (flush, finish the file).
  virtual Status Finish() { return Status::Ok(); }
  // True if it draws the model: only then does the run load it whole (textures at full size,
  // cameras, lights, the world's non-colliding geoms and the sites nothing names: see
  // sim/plant.cc, LoadPlantModel).
  virtual bool Draws() const { return false; }
};

}  // namespace recruit
