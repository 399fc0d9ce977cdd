// The population Kalman filter (src/estimation) as an on-count estimator: the filter's state is
// the count of units per model state; the on-count is the sum over the states whose heater is on
// (BroadcastTransitionModel::is_on). For the augmented transient model these are the heating
// chain and the hot settled state, so a unit that has just been switched on counts as on at once
// although its force is still a fraction of a settled unit's.
#pragma once

#include <memory>

#include "control/on_count_estimator.h"
#include "estimation/filter_model.h"
#include "estimation/population_kalman_filter.h"

namespace recruit::control {

class KalmanOnCountEstimator final : public OnCountEstimator {
 public:
  // `model` must be a single-output model with a broadcast transition; the filter starts from
  // the model's initial belief (x0, P0) and Reset returns to it.
  static Result<std::unique_ptr<KalmanOnCountEstimator>> Create(const FilterModel& model,
                                                                CovarianceMode mode);

  void Reset() override;
  void Observe(double measured_force) override;
  void Broadcasted(const Broadcast& b) override;
  double EstimatedOn() const override { return on_mask_.dot(filter_.estimate()); }
  double EstimatedOnVariance() const override {
    return on_mask_.dot(filter_.covariance() * on_mask_);
  }
  Eigen::VectorXd StateEstimate() const override { return filter_.estimate(); }
  std::vector<std::string> StateNames() const override { return model_.state_names; }
  std::vector<bool> OnStates() const override { return model_.broadcast.is_on; }

  const FilterModel& model() const { return model_; }
  const PopulationKalmanFilter& filter() const { return filter_; }

 private:
  KalmanOnCountEstimator(FilterModel model, PopulationKalmanFilter filter);

  FilterModel model_;
  PopulationKalmanFilter filter_;
  Eigen::VectorXd on_mask_;  // 1 for the "on" states
  Eigen::VectorXd y_;        // workspace (one output)
};

}  // namespace recruit::control
