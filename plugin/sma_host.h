// SmaHost: the host API of a model's SMA bundles, for programs that drive them (the recruitment
// controller, identification, renderers, tests). It reads and writes the units' state in
// mjData.plugin_state; the engine plugin (sma_plugin.h) does the physics inside mj_step.
//
// Bundles are numbered b = 0.. in actuator order over every recruit.sma actuator of the model.
// Host loop: Create, Reset(d, seed), then per step Broadcast (at control instants) and mj_step.
// Hosts that broadcast through Broadcast leave the bundles' ctrl at 0.
#pragma once

#include <mujoco/mujoco.h>

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "common/result.h"
#include "plugin/bundle.h"
#include "plugin/sma_instance.h"

namespace recruit::sma {

class SmaHost {
 public:
  // The recruit.sma bundles of `m` (which must outlive the host). Error when there is none.
  static Result<std::unique_ptr<SmaHost>> Create(const mjModel* m);

  const mjModel* model() const { return m_; }
  int num_bundles() const { return static_cast<int>(refs_.size()); }
  int BundleIndex(std::string_view actuator_name) const;  // -1 if none
  const std::string& bundle_name(int b) const { return bundle(b).config().actuator; }
  int actuator_id(int b) const { return Act(b).actuator; }
  int tendon_id(int b) const { return Act(b).tendon; }
  int num_units(int b) const { return bundle(b).num_units(); }
  const SmaBundle& bundle(int b) const { return Act(b).model; }
  // Steady tension of one unit held on at the reference length (N).
  double SettledUnitForce(int b) const { return Act(b).settled_force; }
  // Tendon length (m) at which a unit's extension is its prestretch.
  double ref_length(int b) const { return Act(b).ref_length / Act(b).gear; }
  // Transmission ratio of bundle b's actuator (gear): the unit extension is
  // prestretch + gear (L - ref_length) for tendon length L, and the tendon's tension is gear x
  // the bundle's (Force).
  double gear(int b) const { return Act(b).gear; }
  // Bundle b's length coordinate, in which its units stretch one for one: gear x its tendon's
  // length (the actuator length), and the value of it at which a unit's extension is its
  // prestretch. With gear 1 these are the tendon's length and ref_length.
  double UnitLength(const mjData* d, int b) const {
    return Act(b).gear * d->ten_length[Act(b).tendon];
  }
  double unit_ref_length(int b) const { return Act(b).ref_length; }
  // The load-time warnings about bundle b's instance (design limits, fit to the tendon), as
  // loading printed them once per model.
  std::vector<std::string> LoadWarnings(int b) const { return Inst(b).LoadWarnings(m_); }

  // Every unit of every bundle off, cold, at the current tendon lengths; bundle b's stream
  // seeded with Rng::DeriveSeed(seed, b). Keeps qpos, qvel and time; ends with mj_forward.
  void Reset(mjData* d, std::uint64_t seed) const;
  // mj_resetDataKeyframe(m, d, key), then Reset(d, seed). Error (d untouched) without keyframe.
  Status ResetKeyframe(mjData* d, int key, std::uint64_t seed) const;

  // Each unit of bundle b draws its transition (off->on with p_on, on->off with p_off).
  Status Broadcast(mjData* d, int b, double p_on, double p_off) const;

  // Starts bundle b's broadcast census (CensusConfig: heaters forced on, then off, for a few ms
  // from the next mj_step). Error when b has no census key or a census is running.
  Status Census(mjData* d, int b) const;
  // The shunt's readings of bundle b's last finished census (SmaBundle::CensusReading).
  SmaBundle::CensusReading LastCensus(const mjData* d, int b) const {
    return bundle(b).LastCensus(State(d, b));
  }

  // Ground truth and telemetry.
  int OnCount(const mjData* d, int b) const { return bundle(b).OnCount(State(d, b)); }
  // Working, open and stuck units of bundle b (all working without failure keys).
  SmaBundle::FailureCounts Failures(const mjData* d, int b) const {
    return bundle(b).Failures(State(d, b));
  }
  double Force(const mjData* d, int b) const;  // bundle tension (N) at the current tendon length
  // OnCount, Force, MeanTemperature, MeanXi, and the peak-relevant MaxTemperature and
  // MaxWireStress (SmaBundle) of bundle b in one pass, each bit for bit the same value: for run
  // loops that read several of them after every step.
  SmaBundle::Telemetry ReadTelemetry(const mjData* d, int b) const {
    return bundle(b).ReadTelemetry(State(d, b), Stretch(d, b));
  }
  // Has each mj_step keep bundle b's telemetry (SmaBundle::ObserveEachStep), so that
  // ReadTelemetry after the step reads it instead of summing the cohorts again: for a run loop
  // that reads it after every step. Until the bundle's next reset (which clears the request).
  void ObserveEachStep(mjData* d, int b) const { SmaBundle::ObserveEachStep(State(d, b), true); }
  double MeanTemperature(const mjData* d, int b) const {
    return bundle(b).MeanTemperature(State(d, b));
  }
  double MeanXi(const mjData* d, int b) const { return bundle(b).MeanXi(State(d, b)); }
  double Heat(const mjData* d, int b) const { return bundle(b).Heat(State(d, b)); }
  int NumCohorts(const mjData* d, int b) const { return bundle(b).NumCohorts(State(d, b)); }
  bool UnitOn(const mjData* d, int b, int i) const { return bundle(b).UnitOn(State(d, b), i); }
  double UnitTemperature(const mjData* d, int b, int i) const {
    return bundle(b).UnitTemperature(State(d, b), i);
  }
  double UnitXi(const mjData* d, int b, int i) const { return bundle(b).UnitXi(State(d, b), i); }
  int UnitCohort(const mjData* d, int b, int i) const {
    return bundle(b).UnitCohort(State(d, b), i);
  }
  // Unit extension (m) of bundle b at the tendon length in d. Inline, as State: a run loop
  // reads every bundle's telemetry after every step.
  double Stretch(const mjData* d, int b) const {
    return Inst(b).Stretch(refs_[b].k, SmaInstance::Length(m_, d, actuator_id(b)));
  }

  // Bundle b's block in plugin_state (SmaBundle layout).
  const double* State(const mjData* d, int b) const {
    return Inst(b).State(d->plugin_state, m_, refs_[b].k);
  }
  double* State(mjData* d, int b) const { return Inst(b).State(d->plugin_state, m_, refs_[b].k); }

 private:
  struct Ref {
    int instance;  // index into instances_
    int k;         // actuator within the instance
  };
  const SmaActuator& Act(int b) const {
    return instances_[refs_[b].instance]->actuators()[refs_[b].k];
  }
  const SmaInstance& Inst(int b) const { return *instances_[refs_[b].instance]; }

  const mjModel* m_ = nullptr;
  std::vector<std::shared_ptr<const SmaInstance>> instances_;
  std::vector<Ref> refs_;
};

}  // namespace recruit::sma
