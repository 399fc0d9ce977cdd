// SmaInstance: the SMA bundles of one recruit.sma plugin instance of a compiled MuJoCo model.
// Immutable after Create (parsed config, unit model, actuator and tendon ids); every unit's state
// lives in the instance's block of mjData.plugin_state, so mj_copyData forks a run exactly and
// one mjData per thread steps in parallel. Used by the engine callbacks (sma_plugin.cc) and by
// the host API (sma_host.h).
//
// plugin_state of an instance: for each of its actuators, in actuator order,
//   [0] time of the next ctrl broadcast (s), [1] reserved, then the bundle's block
//   (SmaBundle::StateSize(units) doubles; layout in plugin/README.md).
#pragma once

#include <mujoco/mujoco.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "common/result.h"
#include "plugin/bundle.h"

namespace recruit::sma {

inline constexpr const char* kPluginName = "recruit.sma";

// Config keys of the binding, besides BundleConfig::Keys().
inline constexpr const char* kSeedKey = "seed";
inline constexpr const char* kBroadcastPeriodKey = "broadcast_period";

// Values a recruit.sma sensor reports per bundle, in this order.
inline constexpr int kSensorValues = 4;  // on count, tension (N), mean T (C), mean xi
// With failure keys in the config: kSensorValues, then working, open and stuck counts.
inline constexpr int kFailureSensorValues = 7;

struct SmaActuator {
  int actuator = -1;  // actuator id
  int tendon = -1;    // tendon id
  int bundle = -1;    // index among all recruit.sma actuators of the model (seed stream)
  int offset = 0;     // start of this actuator's slots in the instance's plugin_state
  // Actuator length (m, gear x tendon length) at which a unit's extension is its prestretch.
  double ref_length = 0;
  double settled_force = 0;  // steady tension of one unit held on at the prestretch (N)
  SmaBundle model;
  double gear = 1;  // transmission: units stretch gear x the tendon's change, pull it gear x
};

// How a bundle fits its tendon over the joint limits: the tendon's length
// range when the limited hinge and slide joints that move it are sampled over their ranges
// (other joints at qpos0), against the units' stroke and forces.
struct TendonFit {
  int joints = 0;            // limited hinge/slide joints that move the tendon (0: no check)
  std::string joint_ranges;  // usable ranges, e.g. "elbow 0..113.9 deg", for messages
  int num_jumps = 0;         // tendon-path jumps found (plugin/tendon_range.h)
  std::string jumps;         // e.g. "elbow at 114 deg (376.0 -> 211.0 mm)"
  double gear = 1;           // the actuator's transmission ratio
  double length_min = 0;     // tendon length range over the usable ranges (m)
  double length_max = 0;
  double stretch_min = 0;  // unit extension at length_min / length_max (m)
  double stretch_max = 0;
  double stroke = 0;             // a unit's recoverable stretch (m, whole unit)
  double on_force = 0;           // all units on, settled at the prestretch (N)
  double off_force = 0;          // all units off (martensite) at stretch_max (N)
  double off_stress = 0;         // wire stress of an off unit at stretch_max (Pa)
  double rated_stress = 0;       // datasheet limit (Pa)
  int series_needed = 0;         // smallest series whose stroke covers the excursion
  double prestretch_needed = 0;  // with it: off units just taut at length_max (m)
  double excursion() const { return length_max - length_min; }
  // Off units stretched past their stroke at the longest tendon (they resist the joint), or on
  // units slack before the shortest (they cannot pull the joint to that end); 5 % of the
  // stroke tolerated.
  bool blocks() const { return joints > 0 && stretch_max > 1.05 * stroke; }
  bool slack() const { return joints > 0 && stretch_min < -0.05 * stroke; }
  bool fits() const { return !blocks() && !slack(); }
};

class SmaInstance {
 public:
  static constexpr int kSlots = 2;  // per actuator, before the bundle's block
  static constexpr int kNextBroadcastSlot = 0;

  // Parses and validates the instance's config and actuators. Errors name the actuator, the
  // config key, its value and what is allowed. Null (no units) inside a fit check's scratch data.
  static Result<std::unique_ptr<SmaInstance>> Create(const mjModel* m, int instance);
  // plugin_state doubles the instance needs (0 when its config is invalid: Create reports it).
  // Called by the compiler before the actuators' transmissions are filled in: reads only the
  // config and which actuators use the instance.
  static int StateSize(const mjModel* m, int instance);
  // Values a sensor on the instance reports per bundle (kSensorValues, or kFailureSensorValues
  // when its config gives a failure key); kSensorValues for an invalid config.
  static int SensorValues(const mjModel* m, int instance);
  int sensor_values() const {
    return actuators_.front().model.has_failures() ? kFailureSensorValues : kSensorValues;
  }

  int instance() const { return instance_; }
  const std::vector<SmaActuator>& actuators() const { return actuators_; }
  std::uint64_t seed() const { return seed_; }
  double broadcast_period() const { return broadcast_period_; }

  // The fit of each actuator's bundle to its tendon (in actuator order). Builds a scratch mjData
  // (mj_makeData runs every plugin's init: a thread_local flag keeps this from recursing).
  std::vector<TendonFit> Fit(const mjModel* m) const;
  // What loading the model warns of (once per distinct model, through mju_warning): each
  // bundle's design past its wire's long-life limits, and each misfit to its tendon.
  // Computed once per distinct model (its content) and instance.
  std::vector<std::string> LoadWarnings(const mjModel* m) const;
  // The warning text for actuator k, or "" when it fits.
  std::string FitWarning(const mjModel* m, int k, const TendonFit& fit) const;

  // The engine's callbacks. `block` is the instance's plugin_state.
  void Reset(const mjModel* m, double* block) const;  // every unit off at actuator_length0
  // Compute and Sensor change no unit: the sensor keeps its tension in the block for Compute,
  // which takes it (SmaBundle::SummarizeAndKeep, TakeTension).
  void Compute(const mjModel* m, mjData* d) const;  // actuator_force = -tension
  void Advance(const mjModel* m, mjData* d) const;  // ctrl broadcasts, then one timestep
  void Sensor(const mjModel* m, mjData* d) const;   // sensor_values() per actuator

  // Unit extension (m) of actuator k at actuator length `length` (gear x tendon length).
  double Stretch(int k, double length) const {
    const SmaActuator& a = actuators_[k];
    return a.model.config().unit.prestretch + (length - a.ref_length);
  }
  double* State(double* plugin_state, const mjModel* m, int k) const {
    return plugin_state + m->plugin_stateadr[instance_] + actuators_[k].offset + kSlots;
  }
  const double* State(const double* plugin_state, const mjModel* m, int k) const {
    return plugin_state + m->plugin_stateadr[instance_] + actuators_[k].offset + kSlots;
  }
  double& NextBroadcast(mjData* d, const mjModel* m, int k) const {
    return d
        ->plugin_state[m->plugin_stateadr[instance_] + actuators_[k].offset + kNextBroadcastSlot];
  }
  // Current actuator length of `actuator` (m, gear x its tendon's length).
  static double Length(const mjModel* m, const mjData* d, int actuator) {
    return d->actuator_length[m->actuator_outadr[actuator]];
  }

 private:
  std::vector<std::string> ComputeLoadWarnings(const mjModel* m) const;
  SmaInstance() = default;
  // check_actuators = false skips the checks of the actuators' transmission and dynamics.
  static Result<std::unique_ptr<SmaInstance>> Build(const mjModel* m, int instance,
                                                    bool check_actuators);

  int instance_ = -1;
  std::uint64_t seed_ = 0;
  double broadcast_period_ = 0;
  int state_size_ = 0;
  std::vector<int> sensor_adr_;  // sensordata address of each sensor on this instance
  std::vector<SmaActuator> actuators_;
};

// The registered slot of recruit.sma, or -1 when the plugin is not registered in this process.
int SmaPluginSlot();
// True when instance `instance` of `m` is a recruit.sma instance.
bool IsSmaInstance(const mjModel* m, int instance);

// `s` cut to at most `max` characters at its last "; " or ", " (whole entries, then "..."), so a
// warning never cuts a joint's range inside its number or unit; cut at `max` only when no
// separator comes before it.
std::string ClipEntries(const std::string& s, size_t max);

}  // namespace recruit::sma
