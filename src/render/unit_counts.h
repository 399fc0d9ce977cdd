// The working, open and stuck units of each bundle a render shows, read from the model's truth
// sensor: the plugin's sensor reports them after each bundle's four values (7 per bundle) when
// the bundle's instance has failure keys (plugin/README.md "Sensor"). Bundles without failure
// keys (4 values per bundle) or without a truth sensor have none, and renders stay as they were.
// The reader evaluates the sensors on its own copy of the model and of the state (mj_getState /
// mj_setState, then mj_forward), leaving the run's data untouched: a run's plant computes no
// sensor (sim/plant.cc turns them off), and sensordata after mj_step is that of the step's start.
#pragma once

#include <mujoco/mujoco.h>

#include <optional>
#include <string>
#include <vector>

#include "common/mujoco_ptr.h"
#include "common/telemetry.h"

namespace recruit::render {

struct UnitCounts {
  int working = 0, open = 0, stuck = 0;
  int total() const { return working + open + stuck; }
};

class UnitCountReader {
 public:
  // One entry per bundle of `sample`, in its order.
  std::vector<std::optional<UnitCounts>> Read(const mjModel* m, const mjData* d,
                                              const TelemetrySample& sample);

 private:
  const mjModel* source_ = nullptr;  // the model the copy below was made from
  ModelPtr model_;                   // its copy with sensors on
  DataPtr data_;
  std::vector<mjtNum> state_;
};

// "54 of 60 working (5 open, 1 stuck)": the zero counts left out.
std::string WorkingText(const UnitCounts& c);

}  // namespace recruit::render
