// TelemetrySample: what the closed loop knows after a physics step, handed to observers (CSV
// writer, video recorder). Shared by src/sim (producer) and src/render (consumer).
#pragma once

#include <limits>
#include <string>
#include <vector>

namespace recruit {

struct BundleTelemetry {
  std::string actuator;     // actuator name in the model
  int tendon_id = -1;       // tendon the bundle pulls (for colouring it in renders)
  double force = 0;         // tension, N
  int true_on = 0;          // units on (ground truth, the paper's debug interface)
  double estimated_on = 0;  // the estimator's on-count (NaN when none)
  // Standard deviation of estimated_on (NaN when the estimator gives none, e.g. output only);
  // `recruit plot` draws estimated_on +- 2 std as the filter's band.
  double estimated_on_std = std::numeric_limits<double>::quiet_NaN();
  double on_fraction = 0;       // true_on / num_units
  double mean_temperature = 0;  // deg C over all units
  // 0 at ambient .. 1 at the on-state steady temperature; computed only for a run with an
  // observer that draws (StepObserver::Draws: the tendons' colour), else NaN.
  double heat = std::numeric_limits<double>::quiet_NaN();
  double force_reference = 0;  // N, the force the bundle's recruitment controller tracks
  double p_on = 0, p_off = 0;  // the bundle's last broadcast
  // N, the load cell's reading at the last control instant, as the controller saw it (held
  // between instants; NaN before the first).
  double sensed_force = std::numeric_limits<double>::quiet_NaN();
  // The failure-aware estimator's count of units still working (NaN for other estimators).
  double estimated_working = std::numeric_limits<double>::quiet_NaN();
};

// A driven joint after the first of a several-joint task (the first is `reference`/`angle`).
struct JointTelemetry {
  std::string joint;
  double reference = 0, angle = 0;  // rad
};

struct TelemetrySample {
  double time = 0;             // s
  double reference = 0;        // the tracked quantity's reference (N or rad, see `reference_unit`)
  double measured = 0;         // the tracked quantity as measured
  std::string reference_unit;  // "N" or "rad"
  double angle = 0;            // joint angle of the limb's main joint, rad (0 on a bench)
  double p_on = 0, p_off = 0;  // last broadcast (of the first bundle; each bundle has its own)
  bool control_instant = false;        // true on steps where the controller broadcast
  std::vector<JointTelemetry> joints;  // the other driven joints (several-joint tasks)
  std::vector<BundleTelemetry> bundles;
};

}  // namespace recruit
