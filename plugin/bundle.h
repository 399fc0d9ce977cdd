// SmaBundle: N identical SMA units pulling one tendon, with each unit's on/off state machine.
// MuJoCo-free: every mutable quantity lives in a caller-owned block of doubles (the plugin puts
// it in mjData.plugin_state), so copying the block forks the bundle exactly.
//
// Units with identical state form a cohort (count + state); per-step cost scales with the number
// of cohorts, not units. A broadcast splits a cohort when some of its units switch; cohorts whose
// states coincide within (merge_temperature, merge_xi) are merged again, and with
// unit_model=binned the nearest are merged further until at most `bins` remain (Bin).
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "common/result.h"
#include "plugin/bundle_config.h"
#include "plugin/unit_model.h"

namespace recruit::sma {

class SmaBundle {
 public:
  // dt: the step it will usually advance by (its exp(-dt/tau) is precomputed).
  static Result<SmaBundle> Create(const BundleConfig& config, double dt);

  // Doubles of state needed for `units` units without failures; with a failure block
  // (config().failure.given), FailureBlockSize(units) more after them.
  static int StateSize(int units) { return kHeader + (kFields + 1) * units; }
  static int FailureBlockSize(int units) { return kFailHeader + 2 * units; }
  // With a census block (config().census.given), kCensusBlock more after those.
  int state_size() const {
    return StateSize(config_.units) + (failures_ ? FailureBlockSize(config_.units) : 0) +
           (census_ ? kCensusBlock : 0);
  }
  bool has_failures() const { return failures_; }
  bool has_census() const { return census_; }

  const BundleConfig& config() const { return config_; }
  const UnitModel& unit() const { return unit_; }
  int num_units() const { return config_.units; }

  // All units off, cold martensite at ambient (one cohort); seeds the bundle's random stream.
  void Reset(double* s, std::uint64_t seed, double stretch) const;
  // False for a block that was never reset (e.g. zeroed by mj_resetData).
  static bool Initialized(const double* s);

  // Every unit draws once from the bundle's stream: an off unit turns on with probability p_on,
  // an on unit turns off with probability p_off. Probabilities must be in [0, 1].
  // Time accumulated since the last unit update (update_period > 0) is integrated first, with
  // the units' old on/off states, at extension `stretch` (m).
  Status Broadcast(double* s, double p_on, double p_off, double stretch) const;

  // Advances every cohort by dt at unit extension `stretch` (m); with update_period > 0 the
  // units are integrated once the accumulated time reaches it (exact thermal step, implicit
  // phase solve: both stay accurate for long steps). When the block asks for it
  // (ObserveEachStep) and `observe_stretch` is a number, the bundle's telemetry at that
  // extension is kept in the block for ReadTelemetry, from the update's own pass over the
  // cohorts where it can (UnitModel::AdvanceCohorts with BatchObserve).
  void Advance(double* s, double stretch, double dt, double observe_stretch = NAN) const;
  // Asks each Advance of this block for its telemetry (a run loop that reads it after every
  // step: the engine plugin gives the extension at the tendon's length as it then is). Reset
  // clears the request.
  static void ObserveEachStep(double* s, bool on) { s[kObserveSlot] = on ? 1 : 0; }

  // The broadcast census (CensusConfig): from the next Advance, every heater forced on for
  // census.on s, then off for census.off s, then back to its latch. Pending time (update_period)
  // is integrated first. Error without a census block or while a census runs.
  Status StartCensus(double* s, double stretch) const;
  bool CensusRunning(const double* s) const;
  // The shunt's readings of the last finished census (A; 0 before the first) and how many
  // censuses have finished since Reset. A reading is (conducting units) x UnitCurrent() plus
  // Gaussian noise of std census.noise, taken at the end of its phase.
  struct CensusReading {
    int number = 0;
    double on_current = 0, off_current = 0;
  };
  CensusReading LastCensus(const double* s) const;
  // One conducting unit's supply current (A): `current` through each of its `parallel` wires
  // (its series segments carry the same current).
  double UnitCurrent() const { return config_.unit.current * config_.unit.parallel; }

  // Total tension of the bundle (N, >= 0) at unit extension `stretch`: pure, reads s only
  // (the "compute" step of a MuJoCo actuator plugin).
  double Tension(const double* s, double stretch) const;
  // Rate of the actuator's MuJoCo-integrated state: none, all state advances in Advance.
  double ActDot(const double* s) const { return 0; }

  int OnCount(const double* s) const;
  // Units by failure state (all working without a failure block). Stuck units are heated and
  // count as on in OnCount; open ones never heat.
  struct FailureCounts {
    int working = 0, open = 0, stuck = 0;
  };
  FailureCounts Failures(const double* s) const;
  // Unit i's failure state: 0 working, 1 open, 2 stuck; its fatigue force scale (1 = fresh).
  int UnitFailure(const double* s, int i) const;
  double UnitForceScale(const double* s, int i) const;
  // The fatigue law (FailureConfig): force scale after damage D (reference cycles).
  double ForceScale(double damage) const;
  // OnCount, Tension, MeanTemperature and MeanXi (the plugin's sensor) in one pass, with the
  // same values.
  struct Summary {
    int on_count;
    double tension, mean_temperature, mean_xi;
  };
  Summary Summarize(const double* s, double stretch) const;
  // What a run loop reads after each step, in one pass over the cohorts: each value the same,
  // bit for bit, as OnCount, Tension, MeanTemperature, MeanXi, MaxTemperature and MaxWireStress
  // give (one tension evaluation per cohort serves the sum and the maximum). The values the last
  // Advance kept (ObserveEachStep) when `stretch` is their extension, else summed now.
  struct Telemetry : Summary {
    double max_temperature, max_wire_stress;
  };
  Telemetry ReadTelemetry(const double* s, double stretch) const {
    if (s[kTelemetrySlot] == 1 && s[kTelemetrySlot + 1] == stretch) return KeptTelemetry(s);
    return SumTelemetryNow(s, stretch);
  }

  // The plugin's sensor and actuator force in one mj_forward (the sensor runs first, at the
  // position stage): SummarizeAndKeep is Summarize and also keeps the tension with its extension
  // in the block; TakeTension returns the kept tension when `stretch` is that extension, else
  // Tension(s, stretch), and clears what was kept either way, so a full mj_forward leaves the
  // block as it was. Reset, Broadcast and Advance clear it too (the units change).
  Summary SummarizeAndKeep(double* s, double stretch) const;
  double TakeTension(double* s, double stretch) const;
  int NumCohorts(const double* s) const { return static_cast<int>(s[kCohortCountSlot]); }
  double MeanTemperature(const double* s) const;
  double MeanXi(const double* s) const;
  // 0 at ambient, 1 at the steady on-temperature (austenite): for colouring tendons.
  double Heat(const double* s) const;

  // Peak-relevant values now, for a run loop that tracks peaks and warns against limits():
  // the hottest unit's temperature (C) and the highest wire stress (Pa) at unit extension
  // `stretch` (UnitModel::WireStress of the most tensioned cohort).
  double MaxTemperature(const double* s) const;
  double MaxWireStress(const double* s, double stretch) const;
  // Datasheet limits for the units' wire diameter (UnitLimits::ForWire).
  const UnitLimits& limits() const { return limits_; }

  // Per-unit debug interface (ground truth).
  int UnitCohort(const double* s, int i) const;
  bool UnitOn(const double* s, int i) const;
  double UnitTemperature(const double* s, int i) const;
  double UnitXi(const double* s, int i) const;

  // Steady tension of one unit held on at `stretch` (N): "count = force / this" for estimators
  // that see only the force.
  double SettledOnTension(double stretch) const;

 private:
  // Summary from the sums of UnitModel::SumTelemetry (on, temperature, xi, tension) over k cohorts.
  Summary FromSums(const double* sum, int k) const;
  // ReadTelemetry's pass over the cohorts; the telemetry the block keeps.
  Telemetry SumTelemetryNow(const double* s, double stretch) const;
  static Telemetry KeptTelemetry(const double* s);
  // Keeps the telemetry at `stretch` after an Advance, from the update's pass (obs, done).
  void KeepTelemetry(double* s, double stretch, const BatchObserve& obs) const;
  // Header: magic, the random stream's 4 words as 8 exact 32-bit halves (low, high), cohort
  // count, update counter, pending time (s), the kept tension (flag 1 when kept, extension (m),
  // tension (N); all 0 when none), the telemetry request (ObserveEachStep: 1 or 0), the kept
  // telemetry (flag 1 when kept, extension (m), on count, tension (N), mean temperature (C), mean
  // xi, max temperature (C), max wire stress (Pa); all 0 when none), so that the cohort fields
  // start 192 bytes after the block. Every slot is a finite number.
  static constexpr int kHeader = 24;
  static constexpr int kMagicSlot = 0, kRngSlot = 1, kCohortCountSlot = 9, kCounterSlot = 10,
                       kPendingSlot = 11, kKeptSlot = 12, kKeptStretchSlot = 13,
                       kKeptTensionSlot = 14, kObserveSlot = 15, kTelemetrySlot = 16;
  static constexpr int kTelemetrySlots = 8;
  // Cohorts as a structure of arrays: field f of cohort j at kHeader + f * N + j (N = units,
  // the most cohorts there can be), so the batched update loads four cohorts' values at once.
  static constexpr int kFields = 7;
  static constexpr int kCount = 0, kOn = 1, kTemp = 2, kXi = 3, kTeff = 4, kHeatScale = 5,
                       kCoolScale = 6;
  static constexpr int kMergeEvery = 8;  // steps between merge passes
  // The failure block (after the unit index): the failure stream's 8 halves, time since reset
  // (s), the next scheduled event, 6 reserved; then per cohort the failure mode (0 working,
  // 1 open, 2 stuck) and the fatigue damage D.
  static constexpr int kFailHeader = 16;
  static constexpr int kFailRngSlot = 0, kFailTimeSlot = 8, kFailNextSlot = 9;
  static constexpr int kModeWorking = 0, kModeOpen = 1, kModeStuck = 2;
  // The census block (after the failure block, if any): the noise stream's 8 halves, the on and
  // off time still to run (s), the last readings (A), the number of finished censuses, 3
  // reserved.
  static constexpr int kCensusBlock = 16;
  static constexpr int kCensusRngSlot = 0, kCensusOnLeftSlot = 8, kCensusOffLeftSlot = 9,
                       kCensusOnReadingSlot = 10, kCensusOffReadingSlot = 11,
                       kCensusNumberSlot = 12;
  double* CensusBlock(double* s) const {
    return s + StateSize(config_.units) + (failures_ ? FailureBlockSize(config_.units) : 0);
  }
  const double* CensusBlock(const double* s) const {
    return s + StateSize(config_.units) + (failures_ ? FailureBlockSize(config_.units) : 0);
  }
  // Advances dt of which the census's phases take the first part; the rest as usual.
  void AdvanceCensus(double* s, double stretch, double dt) const;
  // The shunt's reading of the units conducting in phase `on` (census forced on / off).
  double CensusReadingNow(double* s, bool on) const;
  double* Fail(double* s) const { return s + StateSize(config_.units); }
  const double* Fail(const double* s) const { return s + StateSize(config_.units); }
  double* Mode(double* s) const { return Fail(s) + kFailHeader; }
  const double* Mode(const double* s) const { return Fail(s) + kFailHeader; }
  double* Damage(double* s) const { return Mode(s) + config_.units; }
  const double* Damage(const double* s) const { return Mode(s) + config_.units; }
  // Moves `units` (working units) to failure `mode`: a cohort whose units all fail changes in
  // place, else its failing units get a new cohort (so cohorts never exceed N).
  void FailUnits(double* s, const std::vector<int>& units, int mode) const;
  // Hazards per hour heated and the schedule, for a step of dt that has just been integrated.
  void StepFailures(double* s, double stretch, double dt) const;
  // Per-cycle hazards of the units that a broadcast switched on (flip[i] and now on).
  void CycleFailures(double* s, const std::vector<char>& flip, double stretch) const;
  // count * force scale per cohort (fatigue), in a scratch array; null without fatigue.
  const double* TensionWeights(const double* s) const;
  SmaBundle(BundleConfig c, UnitModel u, double dt);
  double* Field(double* s, int f) const { return s + kHeader + f * config_.units; }
  const double* Field(const double* s, int f) const { return s + kHeader + f * config_.units; }
  // Copies every field of cohort `from` to cohort `to`.
  void CopyCohort(double* s, int from, int to) const;
  double* UnitIndex(double* s) const { return Field(s, kFields); }
  const double* UnitIndex(const double* s) const { return Field(s, kFields); }
  // Sum over cohorts of count * field f, in four partial sums.
  double CountWeightedSum(const double* s, int f) const;
  void Merge(double* s) const;
  // unit_model=binned, after Merge: merges neighbours in (on, temperature) order with the same
  // on/off state and failure mode, in rounds, the nearest first (largest difference of
  // temperature, xi, branch constants and force scale in units of the merge tolerances), until at
  // most config().bins cohorts remain (or one per on/off state and failure mode).
  void Bin(double* s) const;
  // Forgets a kept tension (SummarizeAndKeep).
  static void DropKept(double* s) {
    s[kKeptSlot] = 0, s[kKeptStretchSlot] = 0, s[kKeptTensionSlot] = 0;
  }
  // Forgets the kept tension and telemetry: the units are about to change.
  static void DropAllKept(double* s) {
    DropKept(s);
    for (int i = 0; i < kTelemetrySlots; ++i) s[kTelemetrySlot + i] = 0;
  }
  void Flush(double* s, double stretch) const;
  // heater: per cohort 0/1, the heaters' state over dt; null = the latches (kOn).
  // With obs (count and stretch set, heater null): the update's telemetry, not done when a merge
  // changed the cohorts after it.
  void Integrate(double* s, double stretch, double dt, const double* heater = nullptr,
                 BatchObserve* obs = nullptr) const;
  // Drops cohorts with count 0 and relabels units; forward[j] >= 0 sends the units of an
  // emptied cohort j to cohort forward[j] (k entries); remap: k ints of scratch.
  void Compact(double* s, const int* forward, int* remap) const;

  BundleConfig config_;
  UnitModel unit_;
  UnitLimits limits_;
  double dt_ = 0, decay_ = 1, period_ = 0, decay_period_ = 1;
  bool failures_ = false, fatigue_ = false, census_ = false;
};

}  // namespace recruit::sma
