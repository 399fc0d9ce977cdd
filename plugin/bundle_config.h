// BundleConfig: one SMA bundle's configuration, parsed and validated from key/value pairs (the
// MJCF <config key value> of a recruit.sma plugin; plugin/README.md lists every key).
#pragma once

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "common/result.h"
#include "plugin/unit_model.h"

namespace recruit::sma {

struct BundleConfig {
  std::string actuator;  // actuator name in the model
  int units = 60;        // N, units in the bundle
  UnitParams unit;       // every unit of a bundle is identical
  // Tendon length (m) at which each unit's extension equals unit.prestretch; NaN = the
  // actuator's length at qpos0 (mjModel.actuator_length0).
  double ref_length = std::nan("");
  // Cohorts of units in the same on/off state whose temperatures differ by at most
  // merge_temperature (C) and whose xi (and branch constants) differ by at most merge_xi are
  // merged (the effective temperature follows from T and xi at the bundle's common length) into one
  // with the count-weighted mean state. The mean temperature and xi are kept, so the bundle's
  // tension moves by ~1e-4 of one unit's force; per-unit debug values are exact only with both set
  // to 0 (then only identical states merge).
  double merge_temperature = 0.5;
  double merge_xi = 0.01;
  // Units are integrated every update_period seconds (rounded to whole timesteps) instead of
  // every step; 0 = every step. For long sweeps: the thermal time constant is about 1 s, so a
  // few ms keeps the force within a fraction of a percent at a fraction of the cost.
  double update_period = 0;

  // Parses key/value pairs; an empty value keeps the default (MuJoCo gives "" for a declared key
  // that MJCF did not set). Errors start with `where` and name the key and value.
  static Result<BundleConfig> FromPairs(
      const std::string& actuator, const std::string& where,
      const std::vector<std::pair<std::string, std::string>>& pairs);
  // Whitespace-separated key=value text (tests, tools); errors name the actuator and the key.
  static Result<BundleConfig> FromText(const std::string& actuator, const std::string& text);
  // The accepted keys, in the order of the README's table.
  static std::vector<std::string> Keys();
};

}  // namespace recruit::sma
