// SmaPlugin: the MuJoCo 2.2.2 binding of SMA bundles, shaped like a MuJoCo 3.x actuator plugin
// (configuration parsed from the model, one bundle object per actuator with reset / act_dot /
// compute / advance, one registration function).
//
// MJCF convention (plugin/README.md has the full key table):
//   <size nuserdata="..."/>   at least SmaPlugin::RequiredUserdata (the error says how much)
//   <custom><text name="recruit.sma.NAME" data="units=60 current=0.2 ..."/></custom>
//   <actuator><general name="NAME" tendon="..." dyntype="user" gaintype="user"
//                      biastype="user"/></actuator>
// The actuator's force is -tension (it pulls: shortens the tendon); its act holds the bundle's
// on fraction (written by the host calls, act_dot = 0).
//
// Host loop: Create, Reset(d, seed), then per step Broadcast (at control instants) and
// Step(m, d, plugin) = mj_step + Advance. Callbacks only read mjData, so Euler and RK4 are both
// correct and one mjData per thread can be stepped in parallel.
#pragma once

#include <mujoco/mujoco.h>

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "common/result.h"
#include "plugin/bundle.h"

namespace recruit::sma {

// Installs the process-wide mjcb_act_dyn/gain/bias dispatchers (once; thread-safe). Callbacks
// that were installed before are chained for actuators that are not SMA bundles. Create calls it.
void RegisterSmaCallbacks();

class SmaPlugin {
 public:
  // Parses and validates every recruit.sma.* text of `m`, registers the model. `m` must outlive
  // the plugin; the plugin unregisters itself when destroyed.
  static Result<std::unique_ptr<SmaPlugin>> Create(const mjModel* m);
  ~SmaPlugin();
  SmaPlugin(const SmaPlugin&) = delete;
  SmaPlugin& operator=(const SmaPlugin&) = delete;

  // Size of mjData.userdata that `m`'s bundles need: <size nuserdata> must be at least this.
  // The bundles' blocks start at <custom><numeric name="recruit.sma.userdata_address"> (0).
  static Result<int> RequiredUserdata(const mjModel* m);

  const mjModel* model() const { return m_; }
  int num_bundles() const { return static_cast<int>(bundles_.size()); }
  int BundleIndex(std::string_view actuator_name) const;  // -1 if none
  const std::string& bundle_name(int b) const { return bundles_[b].config().actuator; }
  int actuator_id(int b) const { return actuator_[b]; }
  int tendon_id(int b) const { return tendon_[b]; }
  int num_units(int b) const { return bundles_[b].num_units(); }
  const SmaBundle& bundle(int b) const { return bundles_[b]; }

  // All units of every bundle off, cold, at ambient; bundle b's stream seeded with
  // Rng::DeriveSeed(seed, b). Call after mj_resetData / mj_resetDataKeyframe (they do not
  // restore userdata).
  void Reset(mjData* d, std::uint64_t seed) const;
  // mj_resetDataKeyframe(m, d, key), then Reset(d, seed). Error (and d untouched) if the model
  // has no keyframe `key`.
  Status ResetKeyframe(mjData* d, int key, std::uint64_t seed) const;

  // Each unit of bundle b draws its transition (off->on with p_on, on->off with p_off).
  Status Broadcast(mjData* d, int b, double p_on, double p_off) const;
  // Advances every unit by one timestep at the current tendon lengths (call after mj_step).
  void Advance(mjData* d) const;

  // Ground truth and telemetry.
  int OnCount(const mjData* d, int b) const;
  double Force(const mjData* d, int b) const;            // tension, N, at the current tendon length
  double MeanTemperature(const mjData* d, int b) const;  // C
  double MeanXi(const mjData* d, int b) const;           // mean martensite fraction
  double Heat(const mjData* d, int b) const;             // [0, 1] for render colouring
  int NumCohorts(const mjData* d, int b) const;
  bool UnitOn(const mjData* d, int b, int i) const;
  double UnitTemperature(const mjData* d, int b, int i) const;
  double UnitXi(const mjData* d, int b, int i) const;
  int UnitCohort(const mjData* d, int b, int i) const;
  // Steady tension of one unit held on at the reference length (N).
  double SettledUnitForce(int b) const { return settled_force_[b]; }

  // Unit extension (m) of bundle b at the tendon length in d.
  double Stretch(const mjData* d, int b) const;

  // Callback bodies (pure).
  double ActDot(const mjData* d, int actuator) const {
    const int b = bundle_of_actuator_[actuator];
    return bundles_[b].ActDot(State(d, b));
  }
  double Gain(const mjData* d, int actuator) const { return 0; }
  double Bias(const mjData* d, int actuator) const;
  int BundleOfActuator(int actuator) const { return bundle_of_actuator_[actuator]; }

 private:
  SmaPlugin() = default;
  // Everything Create does except the userdata check and registration.
  static Result<std::unique_ptr<SmaPlugin>> Build(const mjModel* m);
  const double* State(const mjData* d, int b) const { return d->userdata + address_[b]; }
  double* State(mjData* d, int b) const { return d->userdata + address_[b]; }
  void EnsureInitialised(mjData* d) const;
  void WriteAct(mjData* d, int b) const;

  const mjModel* m_ = nullptr;
  std::vector<SmaBundle> bundles_;
  std::vector<int> actuator_, tendon_, address_;
  std::vector<double> ref_length_, settled_force_;
  std::vector<int> bundle_of_actuator_;  // nu entries, -1 for other actuators
  int userdata_end_ = 0;                 // one past the last userdata entry used
  bool registered_ = false;
};

// One physics step: mj_step, then plugin.Advance(d).
void Step(const mjModel* m, mjData* d, const SmaPlugin& plugin);

}  // namespace recruit::sma
