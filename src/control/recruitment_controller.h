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

struct ControllerParams {
  int num_units = 60;      // N, units in the bundle
  double unit_force = 0;   // N, settled force of one unit whose heater is on
  double dT = kDefaultDT;  // s, sampling period (control/sampling_period.h)
  double lambda = 0.2;     // gain of the expectation law, in (0, 1]
  // The bundle's unit and tendon geometry: when set, the target count and the estimator use the
  // settled on unit's force at the measured tendon length (UnitForceMap), not at ref_length.
  std::optional<UnitGeometry> geometry;

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
  // stuck units alone exceed it, 0 otherwise (and always 0 without failures).
  int saturation() const { return saturation_; }
  double estimated_working() const { return estimated_working_; }
  double estimated_on_variance() const { return estimated_on_variance_; }
  const Broadcast& last_broadcast() const { return last_; }

 private:
  RecruitmentController(const ControllerParams& params, std::unique_ptr<OnCountEstimator> est,
                        std::optional<UnitForceMap> on_force)
      : params_(params), estimator_(std::move(est)), on_force_(std::move(on_force)) {}

  // The expectation law on the working units (a failure-aware estimator).
  Broadcast FailureAwareLaw(const FailureEstimate& f);

  ControllerParams params_;
  std::unique_ptr<OnCountEstimator> estimator_;
  std::optional<UnitForceMap> on_force_;  // one state: the settled on unit
  double unit_force_ = 0;
  double target_on_ = 0;
  double estimated_on_ = 0;
  double estimated_on_variance_ = 0;
  double estimated_working_ = 0;
  int saturation_ = 0;
  Broadcast last_;
};

}  // namespace recruit::control
