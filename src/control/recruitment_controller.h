// RecruitmentController: one bundle's broadcast controller, an on-count estimator wired to the
// expectation law. Call Step once per sampling period dT with the force reference and the
// force measured at that instant; broadcast what it returns to the bundle.
#pragma once

#include <memory>

#include "common/result.h"
#include "control/broadcast.h"
#include "control/on_count_estimator.h"

namespace recruit::control {

struct ControllerParams {
  int num_units = 60;     // N, units in the bundle
  double unit_force = 0;  // N, settled force of one unit whose heater is on
  double dT = 0.5;        // s, sampling period
  double lambda = 0.2;    // gain of the expectation law, in (0, 1]

  // Checks N >= 1, unit_force > 0, dT > 0, 0 < lambda <= 1 (finite); the message names the field.
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

  // One control instant: estimator.Observe(measured), target = reference / unit_force,
  // b = ExpectationLaw(target, estimated on, N, lambda), estimator.Broadcasted(b).
  Broadcast Step(double reference_force, double measured_force);

  const ControllerParams& params() const { return params_; }
  const OnCountEstimator& estimator() const { return *estimator_; }
  // Values at the last Step: the target on-count and the a-posteriori estimate the law used.
  double target_on() const { return target_on_; }
  double estimated_on() const { return estimated_on_; }
  double estimated_on_variance() const { return estimated_on_variance_; }
  const Broadcast& last_broadcast() const { return last_; }

 private:
  RecruitmentController(const ControllerParams& params, std::unique_ptr<OnCountEstimator> est)
      : params_(params), estimator_(std::move(est)) {}

  ControllerParams params_;
  std::unique_ptr<OnCountEstimator> estimator_;
  double target_on_ = 0;
  double estimated_on_ = 0;
  double estimated_on_variance_ = 0;
  Broadcast last_;
};

}  // namespace recruit::control
