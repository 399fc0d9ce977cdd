// Editing a copy of a user's MJCF through MuJoCo's model-editing API (mjSpec): a tendon actuator
// becomes a recruit.sma bundle with its own plugin instance and truth sensor, under a default
// class that undoes inherited muscle (or other) activation, gain and bias defaults; asset
// directories are rebased so the written model loads from its new folder.
#pragma once

#include <mujoco/mujoco.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "common/mujoco_ptr.h"
#include "common/mujoco_warnings.h"
#include "common/result.h"

namespace recruit::attach {

struct SpecDeleter {
  void operator()(mjSpec* s) const { mj_deleteSpec(s); }
};
using SpecPtr = std::unique_ptr<mjSpec, SpecDeleter>;

// The class the bundles use: MuJoCo's built-in actuator defaults (no dynamics, fixed unit gain,
// no bias), whatever the model's main class says.
inline constexpr const char* kBundleClass = "recruit_sma";

Result<SpecPtr> ParseSpec(const std::string& path);
Result<SpecPtr> CopySpec(const mjSpec* spec);
// Compiles (the spec keeps the compiled values); the error is MuJoCo's.
Result<ModelPtr> CompileSpec(mjSpec* spec);

std::vector<std::string> ActuatorNames(const mjSpec* spec);  // spec (= compiled) order
// Actuators with muscle gain on a tendon, in order.
std::vector<std::string> TendonMuscleNames(const mjSpec* spec);
mjsActuator* FindActuator(const mjSpec* spec, const std::string& name);
// A tendon actuator by name, or an error naming it and what is allowed.
Result<mjsActuator*> FindTendonActuator(const mjSpec* spec, const std::string& name);

// A name of `type` not used in the spec: base, else base_2, base_3, ...
std::string UniqueName(const mjSpec* spec, mjtObj type, const std::string& base);

struct BundleEdit {
  std::string actuator;  // the actuator replaced (keeps its name)
  std::string instance;  // new plugin instance
  std::string sensor;    // new truth sensor
  double gear = 1;
  double damping = 0;  // N s/m: the actuator's damping (the damper beside the units)
  std::vector<std::pair<std::string, std::string>> config;
};

// Replaces the actuator in place (same name, same tendon, same position in the actuator list).
Status ReplaceWithBundle(mjSpec* spec, const BundleEdit& edit);

// Makes meshdir/texturedir (and relative asset files without a dir) resolve from the folder of
// `output_path` as they did from `input_path`'s.
void RebaseAssetDirs(mjSpec* spec, const std::string& input_path, const std::string& output_path);

// The spec as MJCF text.
Result<std::string> SaveXmlString(const mjSpec* spec);

}  // namespace recruit::attach
