// RecruitmentController: one bundle's broadcast controller, an on-count estimator wired to the
// expectation law. Call Step once per sampling period dT with the force reference and the
// force measured at that instant; broadcast what it returns to the bundle.
#pragma once

#include <limits>
#include <memory>
#include <optional>

#include "common/result.h"
#include "control/broadcast.h"
#include "control/on_count_estimator.h"
#include "control/sampling_period.h"

namespace recruit::control {

// Exploration (docs/failures.md "Exploration"), with a failure-aware estimator only: for
// `instants` control instants after a trigger the broadcast switches units both ways so that
// units lost while off (invisible until recruited) show up. `balanced`: at least `p_on` of the
// off units are recruited and as many more on units released as keeps the expected count
// (ExplorationLaw); otherwise ("toggle") every unit switches with probability p_on at the first
// instant (p_on = p_off; with 1, a deterministic swap of the on and off units) and none for the
// other instants-1, so that the switched units settle before the law resumes. Triggers: a
// declared failure (`after_declaration`), the estimator's suspicion (FailureEstimate::suspicion,
// the failure test's largest ratio) reaching `suspicion` (> 0), and every `period` seconds (> 0);
// none within `rest` instants of the end of the last exploration. The default (p_on = 0) never
// explores: the broadcasts are the law's.
struct ExplorationParams {
  double p_on = 0;  // in [0, 1]; 0: off
  bool balanced = true;
  int instants = 10;
  // The control instants after the exploration's first whose force the estimator does not use
  // (it predicts through the switched units' transient, which its chain models least exactly).
  int unmeasured = 0;
  int rest = 0;
  bool after_declaration = true;
  double suspicion = 0;  // log-likelihood ratio; 0: not a trigger
  double period = 0;     // s; 0: not a trigger
};

struct ControllerParams {
  int num_units = 60;      // N, units in the bundle
  double unit_force = 0;   // N, settled force of one unit whose heater is on
  double dT = kDefaultDT;  // s, sampling period (control/sampling_period.h)
  double lambda = 0.2;     // gain of the expectation law, in (0, 1]
  // The bundle's unit and tendon geometry: when set, the target count and the estimator use the
  // settled on unit's force at the measured tendon length (UnitForceMap), not at ref_length.
  std::optional<UnitGeometry> geometry;
  ExplorationParams exploration;
  // The broadcast census (docs/failures.md section 5), with a failure-aware estimator only:
  // every census_period s (rounded to whole control instants P >= 1; 0 = never) census() asks
  // the host to run one in the control period that follows instants P - 1, 2P - 1, ... after
  // Reset (right after broadcasting, or ending at the next instant: the later, the fresher its
  // count); the host hands the shunt's counts to Census() before the next Step.
  double census_period = 0;

  // Checks N >= 1, unit_force > 0, dT (CheckDT), 0 < lambda <= 1 (finite); the message names the
  // field.
  Status Validate() const;
};

class RecruitmentController {
 public:
  static Result<RecruitmentController> Create(const ControllerParams& params,
                                              std::unique_ptr<OnCountEstimator> estimator);
  // Convenience: MakeEstimator(spec, params...) then Create.
  static Result<RecruitmentController> Create(const ControllerParams& params,
                                              const EstimatorSpec& spec);

  // Back to the initial belief (all units off).
  void Reset();

  // One control instant: estimator.UpdateWithMeasurement(measured, length), target = reference /
  // (unit force at that length), b = ExpectationLaw(target, estimated on, N, lambda),
  // estimator.Broadcasted(b). tendon_length NaN: not measured (the force at ref_length).
  Broadcast Step(double reference_force, double measured_force,
                 double tendon_length = std::numeric_limits<double>::quiet_NaN());

  // Whether the host should run a census in the period after the last Step's broadcast.
  bool census() const { return census_; }
  // The last census's counts (working + stuck, stuck; units) and their measurement variance
  // (units^2), before the next Step: the estimator takes them (FailureOnCountEstimator).
  void Census(double conducting, double stuck, double variance);

  const ControllerParams& params() const { return params_; }
  const OnCountEstimator& estimator() const { return *estimator_; }
  // Values at the last Step: the target on-count and the a-posteriori estimate the law used.
  double target_on() const { return target_on_; }
  // Settled force of one on unit at the last Step's tendon length (N).
  double unit_force() const { return unit_force_; }
  // Settled force of one on unit at `tendon_length` (N): what Step would target with.
  double OnUnitForce(double tendon_length) const;
  double estimated_on() const { return estimated_on_; }
  // With a failure-aware estimator (OnCountEstimator::Failures): the law acts on the estimated
  // working units only (stuck ones are on for good and count towards the target, open ones never
  // switch). saturation() at the last Step: +1 when the reference needs more than every working
  // unit (the target is clamped to them: the law asks for all and winds nothing up), -1 when the
  // stuck units alone exceed it, 0 otherwise. Without failures: +1 when the reference needs more
  // than every unit, 0 otherwise.
  int saturation() const { return saturation_; }
  double estimated_working() const { return estimated_working_; }
  // Whether the last Step's broadcast explored (ControllerParams::exploration).
  bool exploring() const { return exploring_; }
  double estimated_on_variance() const { return estimated_on_variance_; }
  const Broadcast& last_broadcast() const { return last_; }

 private:
  RecruitmentController(const ControllerParams& params, std::unique_ptr<OnCountEstimator> est,
                        std::optional<UnitForceMap> on_force)
      : params_(params), estimator_(std::move(est)), on_force_(std::move(on_force)) {}

  // The expectation law on the working units (a failure-aware estimator).
  Broadcast FailureAwareLaw(const FailureEstimate& f);
  // Counts the exploration's triggers and, while one runs, widens the law's broadcast.
  Broadcast Explore(const Broadcast& law, const FailureEstimate& f);

  ControllerParams params_;
  std::unique_ptr<OnCountEstimator> estimator_;
  std::optional<UnitForceMap> on_force_;  // one state: the settled on unit
  double unit_force_ = 0;
  double target_on_ = 0;
  double estimated_on_ = 0;
  double estimated_on_variance_ = 0;
  double estimated_working_ = 0;
  int saturation_ = 0;
  int explore_left_ = 0;     // instants of exploration still to broadcast
  int rest_left_ = 0;        // instants before a trigger may start another
  int unmeasured_left_ = 0;  // instants whose force the estimator is not given
  long since_period_ = 0;    // instants since the last periodic exploration began
  bool exploring_ = false;
  long instants_ = 0;  // Steps since Reset
  bool census_ = false;
  Broadcast last_;
};

}  // namespace recruit::control
