// The martensite fraction of a settled unit, from the plugin's own unit physics: the state a
// transient chain's "hot" (heater on for long) and "cold" (heater off for long after heating)
// stand for (docs/identification.md, "Settled states").
//
// The least-squares refinement of the output fractions (plant_identification.cc) fits every
// state to the excitation's recordings, where the chain's settled states also absorb what the
// chain's geometric dwell times and the units' switching history (minor loops) do not explain:
// on the two-joint arm's shoulder bundles it gave hot 0.035 where a settled unit is fully
// austenite, a hot unit's force 3-6 % low, so that at the controller's holds, where nearly every
// unit is settled, the filter's count was a few units high while its variance fell (NEES 2.3-4.7).
// The settled states are therefore given the fraction of a settled unit, not fitted.
#pragma once

#include <vector>

#include "plugin/unit_model.h"

namespace recruit::identification {

// The fraction of one unit at extension `stretch` (m) settled from rest (cold martensite) with
// the heater on, and with `on` false then settled with it off: the fixed point of the plugin's
// thermal step and phase solve, stepped until the fraction stops changing.
double SettledFraction(const sma::UnitModel& unit, double stretch, bool on);

// The one fraction whose tension best matches (least squares) a settled unit's over the given
// extensions (m; each settled at its own extension): the settled state's fraction for a
// model whose output follows the tendon (control::UnitForceMap). Golden section in [0, 1].
double SettledStateFraction(const sma::UnitModel& unit, const std::vector<double>& stretches,
                            bool on);

}  // namespace recruit::identification
