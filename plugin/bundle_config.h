// BundleConfig: one SMA bundle's configuration, parsed and validated from the key=value text of
// <custom><text name="recruit.sma.ACTUATOR" data="..."> (plugin/README.md lists every key).
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "common/result.h"
#include "plugin/unit_model.h"

namespace recruit::sma {

// Prefix of the <custom><text> element that configures an actuator.
inline constexpr const char* kTextPrefix = "recruit.sma.";

struct BundleConfig {
  std::string actuator;  // actuator name in the model
  int units = 60;        // N, units in the bundle
  UnitParams unit;       // every unit of a bundle is identical
  // Tendon length (m) at which each unit's extension equals unit.prestretch; NaN = the
  // actuator's length at qpos0 (mjModel.actuator_length0).
  double ref_length = std::nan("");
  // Cohorts of units whose states differ by less than these are merged (deg C, fraction).
  double merge_temperature = 1e-3;
  double merge_xi = 1e-5;

  // Parses `text` (whitespace-separated key=value). Errors name the actuator and the key.
  static Result<BundleConfig> FromText(const std::string& actuator, const std::string& text);
  // The accepted keys, in the order of the README's table.
  static std::vector<std::string> Keys();
};

}  // namespace recruit::sma
