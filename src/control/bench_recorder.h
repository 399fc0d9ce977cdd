// Records a switching log on a MuJoCo bench through the SMA plugin's host API: at every control
// instant k (every dT) sample the bundle's force, then broadcast the excitation's (p_on, p_off);
// step the physics until the next instant. The bundle starts all off, at ambient.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "common/result.h"
#include "control/excitation.h"
#include "control/switching_log.h"

namespace recruit::control {

struct BenchRecording {
  SwitchingLog log;
  double unit_force = 0;  // N, the plugin's settled force of one unit (SettledUnitForce)
  double timestep = 0;    // s, the model's physics timestep
  nlohmann::json plant;   // the bundle it was recorded on (control/plant_record.h)
};

// `actuator`: the bundle's actuator name; empty for the model's first bundle.
// dT must be a whole number of physics timesteps (within 1e-9).
Result<BenchRecording> RecordBench(const std::string& model_path, const std::string& actuator,
                                   const Excitation& excitation, double dT, std::uint64_t seed);

}  // namespace recruit::control
