// The population Kalman filter (src/estimation) as an on-count estimator: the filter's state is
// the count of units per model state; the on-count is the sum over the states whose heater is on
// (BroadcastTransitionModel::is_on). For the augmented transient model these are the heating
// chain and the hot settled state, so a unit that has just been switched on counts as on at once
// although its force is still a fraction of a settled unit's.
#pragma once

#include <memory>
#include <optional>

#include "control/on_count_estimator.h"
#include "estimation/filter_model.h"
#include "estimation/population_kalman_filter.h"

namespace recruit::control {

// What every population-filter estimator needs of its inputs: a valid broadcast model with one
// output, a unit force map of as many states, a finite relative noise >= 0.
Status CheckEstimatorInputs(const estimation::FilterModel& model,
                            const std::optional<UnitForceMap>& output, double relative_noise);

class KalmanOnCountEstimator final : public OnCountEstimator {
 public:
  // `model` must be a single-output model with a broadcast transition; the filter starts from
  // the model's initial belief (x0, P0) and Reset returns to it.
  // With `output`, the filter's H follows the measured tendon length (UnitForceMap over the
  // model's states) and R = model R + relative_noise^2 (H x^-)^2: the unit force model's error
  // (units of one state do not all sit at its fraction) grows with the force.
  static Result<std::unique_ptr<KalmanOnCountEstimator>> Create(
      const estimation::FilterModel& model, estimation::CovarianceMode mode,
      std::optional<UnitForceMap> output = std::nullopt, double relative_noise = 0);

  void Reset() override;
  using OnCountEstimator::UpdateWithMeasurement;
  void UpdateWithMeasurement(double measured_force, double tendon_length) override;
  void Broadcasted(const Broadcast& b) override;
  double EstimatedOn() const override { return on_mask_.dot(filter_.estimate()); }
  double EstimatedOnVariance() const override;
  Eigen::VectorXd StateEstimate() const override { return filter_.estimate(); }
  std::vector<std::string> StateNames() const override { return model_.state_names; }
  std::vector<bool> OnStates() const override { return model_.broadcast.is_on; }

  const estimation::FilterModel& model() const { return model_; }
  const estimation::PopulationKalmanFilter& filter() const { return filter_; }
  // The length-dependent output model (none: H fixed) and the relative noise of R (Create).
  const std::optional<UnitForceMap>& output() const { return output_; }
  double relative_noise() const { return relative_noise_; }

 private:
  KalmanOnCountEstimator(estimation::FilterModel model, estimation::PopulationKalmanFilter filter,
                         std::optional<UnitForceMap> output, double relative_noise);

  estimation::FilterModel model_;
  estimation::PopulationKalmanFilter filter_;
  Eigen::VectorXd on_mask_;  // 1 for the "on" states
  Eigen::VectorXd y_;        // workspace (one output)
  std::optional<UnitForceMap> output_;
  double relative_noise_ = 0;
  Eigen::MatrixXd h_, r_;  // workspaces: H (1 x m) and R (1 x 1) at the measured length
};

}  // namespace recruit::control
