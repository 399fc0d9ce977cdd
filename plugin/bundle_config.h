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

// Unit failures and functional fatigue (plugin/README.md "Failures"; docs/failures.md). Off
// unless a failure key is given: then the bundle's block has a failure block and its sensor
// reports the working, open and stuck counts.
struct FailureConfig {
  bool given = false;  // a failure key was given (even 0): the failure block exists
  // Hazards per hour heated (a unit whose heater is on, stuck units excepted) and per
  // transformation cycle (a working unit switched on), into "open" (never heats again) and
  // "stuck" (heated for good).
  double open_rate = 0, stuck_rate = 0;            // 1/h heated
  double open_per_cycle = 0, stuck_per_cycle = 0;  // probability per cycle
  // Scheduled failures: at `time` (s since reset), `count` working units (chosen uniformly by
  // the failure stream) fail open or stuck.
  struct Event {
    double time = 0;
    int count = 0;
    bool stuck = false;
  };
  std::vector<Event> schedule;  // in time order
  // Functional fatigue: a unit's force and recoverable strain scale by
  // s(D) = 1 - fatigue_loss (1 - exp(-D / fatigue_cycles)), D the damage in reference cycles:
  // each heating cycle adds (1 - xi at switch-off) (stress / fatigue_stress)^fatigue_exponent.
  double fatigue_loss = 0;        // asymptotic fraction lost; 0 = no fatigue
  double fatigue_cycles = 100;    // shakedown constant N_p (reference cycles)
  double fatigue_stress = 172e6;  // reference wire stress (Pa)
  double fatigue_exponent = 1.5;  // stress exponent m

  bool any_hazard() const {
    return open_rate > 0 || stuck_rate > 0 || open_per_cycle > 0 || stuck_per_cycle > 0;
  }
  // Parses "t:count:open|stuck[,t:count:mode...]" (times in s, in any order; sorted).
  static Result<std::vector<Event>> ParseSchedule(const std::string& text);
};

// The broadcast census (plugin/README.md "Census"; docs/failures.md section 5). On request
// (SmaHost::Census) every unit's heater is forced on for `on` s, then off for `off` s, whatever
// its latch, and then follows its latch again: no unit is addressed. Open units cannot conduct
// and stuck ones cannot stop, so the bundle's supply current, read by one shunt at the end of
// each phase with Gaussian noise of standard deviation `noise` (A), counts the working plus stuck
// units (on phase) and the stuck ones (off phase). Off unless a census key is given: then the
// bundle's block has a census block.
struct CensusConfig {
  bool given = false;
  double on = 2e-3, off = 2e-3;  // s, the phases' lengths
  double noise = 0.01;           // A, standard deviation of one shunt reading
};

// How a bundle's cohorts are kept (plugin/README.md "Unit models"). kExact: cohorts merge only
// within merge_temperature and merge_xi, so the bundle follows every unit's exact update to ~1e-4
// of one unit's force. kBinned: after each merge pass the cohorts are merged further, the closest
// pairs first, until at most `bins` remain: the per-step cost is bounded by `bins` cohorts, at
// the accuracy docs/sma-units.md states.
enum class UnitModelKind { kExact, kBinned };

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
  UnitModelKind unit_model = UnitModelKind::kExact;
  int bins = 16;  // kBinned: the most cohorts a merge pass leaves
  FailureConfig failure;
  CensusConfig census;

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
