// Records a switching log on a MuJoCo plant through the SMA plugin's host API: at every control
// instant k (every dT) sample the bundle's force, then broadcast the excitation's (p_on, p_off);
// step the physics until the next instant. The bundle starts all off, at ambient.
// On a limb the joints that move the bundle's tendon are held still (a locked-angle bench, as in
// a lab), at a pose chosen by its place in the tendon's length range: by default the longest,
// where every unit that is not fully martensite is taut, so every state's force is seen
// (control/unit_force_map.h carries it to other lengths).
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/result.h"
#include "control/unit_force_map.h"
#include "identification/excitation.h"
#include "identification/switching_log.h"

namespace recruit::identification {

struct BenchRecording {
  SwitchingLog log;
  double unit_force = 0;     // N, the plugin's settled force of one unit (SettledUnitForce)
  double timestep = 0;       // s, the model's physics timestep
  nlohmann::json plant;      // the bundle it was recorded on (identification/plant_record.h)
  double tendon_length = 0;  // m, held: the bundle's length coordinate (gear x its tendon's length,
                             // SmaHost::UnitLength) at the recorded pose, at t = 0
  std::vector<double> lengths;     // m, the tendon's length at each sample
  double stretch = 0;              // m, the units' extension there
  std::string pose;                // e.g. "elbow 0.0 deg", empty when nothing was held
  control::UnitGeometry geometry;  // the bundle's unit and reference length
};

struct RecordOptions {
  // Where to hold the limb: 0 = the shortest tendon length over the joints' ranges, 1 = the
  // longest. The limited hinge or slide joint that moves the tendon the most is set (others
  // stay at qpos0); a model without one (a fixed bench) is recorded as it is.
  double length_place = 1.0;
  // > 0: instead of holding, drive the joint over its range and back with this period (s), to
  // record the units while the tendon moves (the fit's checks; docs/identification.md).
  double sweep_period = 0;
};

// `actuator`: the bundle's actuator name; empty for the model's first bundle.
// dT must be a whole number of physics timesteps (within 1e-9).
Result<BenchRecording> RecordBench(const std::string& model_path, const std::string& actuator,
                                   const Excitation& excitation, double dT, std::uint64_t seed,
                                   const RecordOptions& options = {});

}  // namespace recruit::identification
