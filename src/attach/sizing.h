// Sizing an SMA bundle from the muscle it replaces (MuJoCo-free): a peak force and the tendon's
// excursion over the usable joint ranges in, a buildable bundle of Flexinol-type straight wires
// out (diameter, wires per segment, segments, wire length, current, spring, prestretch, units,
// transmission) with what it costs. The rules and bounds are documented in docs/sma-units.md
// ("Sizing a bundle") and docs/howto-own-model.md.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "common/result.h"
#include "plugin/unit_model.h"

namespace recruit::attach {

// Bounds of a credible unit (docs/sma-units.md, "Sizing a bundle").
struct SizingLimits {
  double max_segment_length = 0.25;  // m of active wire per segment
  int max_series = 4;                // segments per unit: at most 1 m of active wire per unit
  // Fraction of the stroke the excursion uses: the rest is the hot units' stretch at the
  // tendon's shortest, so it sets how steeply a bundle's force falls as it shortens (its own
  // stiffness, which holds a joint whose moment arms grow with the angle).
  double stroke_use = 0.85;
  double design_stress = 0.8 * 172e6;  // Pa: a hot wire's stress at the tendon's longest
  double steady_temperature = 115;     // C: a held-on wire's steady temperature (<= 120)
  int max_units = 100;                 // units per bundle (the controller's resolution)
  int max_parallel = 8;                // wires per segment
  // s: the slowest unit thermal time constant chosen when a thinner wire can meet the force with
  // at most max_parallel wires per segment (0.15 mm wire: 2.0 s; the bundle's bandwidth).
  double max_time_constant = 2.0;
  // Units a bundle of such thinner wires may have; when none within it is fast enough, up to
  // max_units_resolution before a slower wire is taken (and said in the design's notes).
  int max_units_fast = 300;
  double min_segment_length = 0.03;  // m
  // Resolution: at least this many units' force in the load the bundle holds
  // (SizingInput::holding_force), up to max_units_resolution units. 150: one unit then moves a
  // joint held by its weight about 0.4 deg, so that the count errors of several bundles on one
  // joint stay inside a settling band of a few degrees (docs/sma-units.md, "Resolution").
  int units_per_holding_force = 150;
  int max_units_resolution = 1000;
  // A bundle that holds no weight (a limb moving in a horizontal plane) is held by the
  // co-contraction the self-tuned loop keeps, this fraction of its peak force (the task's
  // default co_contraction): the resolution rule takes that as its load.
  double rest_tension_fraction = 0.05;
  // Least damping ratio of every joint the bundles move, at their stiffness at rest, that their
  // dampers give it (attach/damper.h); 0: no dampers.
  double damping_ratio = 0.5;
};

// Stock Flexinol diameters (m), thinnest first.
const std::vector<double>& StockDiameters();

struct SizingInput {
  std::string name;       // the bundle (for messages)
  double peak_force = 0;  // N at the tendon, at full recruitment mid-range
  double excursion = 0;   // m: tendon length range over the usable joint ranges
  double length_min = 0;  // m: the tendon's shortest and longest (usable)
  double length_max = 0;
  double ref_length = 0;     // m: tendon length at qpos0 (the plugin's default ref_length)
  double holding_force = 0;  // N at the tendon that holds its limb's own weight (0: unknown)
};

struct BundleDesign {
  sma::UnitParams unit;  // wire_diameter, wire_length, series, parallel, current, series_spring,
                         // prestretch (whole unit, at ref_length) set; the rest default
  int units = 0;
  double gear = 1;           // transmission (actuator gear): 1 = none, < 1 trades stroke for force
  std::string transmission;  // "" or what to build, e.g. "lever/pulley 0.5:1 (gear 0.5)"
  // Figures from the plugin's own unit physics (sma::UnitModel):
  double force_mid = 0;            // N at the tendon, all units on, mid-range
  double force_short = 0;          // N at the tendon's shortest (all on)
  double force_long = 0;           // N at its longest (all on)
  double peak_stress = 0;          // Pa: hot wire at the tendon's longest
  double steady_temperature = 0;   // C: a held-on wire (austenite)
  double max_current = 0;          // A: Dynalloy's 1 s contraction current for the diameter
  double stroke = 0;               // m: a unit's recoverable stretch (series x eps_L x wire_length)
  double wire_total = 0;           // m of active wire in the bundle
  double mass = 0;                 // kg of active wire
  double power = 0;                // W: every unit on (austenite resistance)
  double time_constant = 0;        // s: the wire's thermal time constant
  double cooling_time = 0;         // s: Dynalloy's still-air cooling time for the diameter
  std::vector<std::string> notes;  // choices a reader should know about
  // N s/m: the damper beside the units, behind the lever (MuJoCo's actuator damping; the tendon
  // sees gear^2 times it). Set by the limb's damper design (attach/damper.h), 0 when none.
  double damper = 0;

  // The units' extension (m) at tendon length L when the tendon is ref_length at qpos0 (the
  // plugin's ref_length): prestretch + gear (L - ref_length).
  double Stretch(double L, double ref_length) const {
    return unit.prestretch + gear * (L - ref_length);
  }

  // The plugin's config keys for this design (value strings).
  std::vector<std::pair<std::string, std::string>> ConfigPairs() const;
};

// Designs the bundle. Error when the input is not finite or not positive.
Result<BundleDesign> SizeBundle(const SizingInput& in, const SizingLimits& limits = {});

}  // namespace recruit::attach
