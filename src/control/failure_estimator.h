// The failure-aware Kalman on-count estimator ("kalman-failures"): KalmanOnCountEstimator's
// observation model (length-aware H, R growing with the force) on the filter with absorbing
// open/stuck states (estimation/failure_filter.h). The on count is the heated units: working
// units in heater-on states plus the stuck ones. Until a failure is declared its estimates are
// those of "kalman-augmented", bit for bit.
#pragma once

#include <memory>
#include <optional>

#include "control/on_count_estimator.h"
#include "estimation/failure_filter.h"
#include "estimation/filter_model.h"

namespace recruit::control {

class FailureOnCountEstimator final : public OnCountEstimator {
 public:
  static Result<std::unique_ptr<FailureOnCountEstimator>> Create(
      const estimation::FilterModel& model, estimation::CovarianceMode mode,
      const estimation::FailureFilterParams& params,
      std::optional<UnitForceMap> output = std::nullopt, double relative_noise = 0);

  void Reset() override { filter_.Reset(); }
  using OnCountEstimator::UpdateWithMeasurement;
  void UpdateWithMeasurement(double measured_force, double tendon_length) override;
  void Broadcasted(const Broadcast& b) override { filter_.PredictBroadcast(b.p_on, b.p_off); }
  // A broadcast census read before this instant's UpdateWithMeasurement: the working plus stuck
  // and the stuck units counted by the shunt (currents over one unit's), with measurement
  // variance `variance` (units^2; FailureKalmanFilter::UpdateCensus).
  void UpdateWithCensus(double conducting, double stuck, double variance) {
    filter_.UpdateCensus(conducting, stuck, variance);
  }
  double EstimatedOn() const override;
  double EstimatedOnVariance() const override;
  // [model states; open: model states; stuck: model states].
  Eigen::VectorXd StateEstimate() const override { return filter_.estimate(); }
  std::vector<std::string> StateNames() const override;
  std::vector<bool> OnStates() const override;
  std::optional<FailureEstimate> Failures() const override;

  const estimation::FilterModel& model() const { return model_; }
  const estimation::FailureKalmanFilter& filter() const { return filter_; }

 private:
  FailureOnCountEstimator(estimation::FilterModel model, estimation::FailureKalmanFilter filter,
                          std::optional<UnitForceMap> output, double relative_noise);

  estimation::FilterModel model_;
  estimation::FailureKalmanFilter filter_;
  Eigen::VectorXd on_mask_;    // 3m: the working heater-on states and every stuck state
  Eigen::VectorXd on_mask_w_;  // its first m entries (the working states)
  std::optional<UnitForceMap> output_;
  double relative_noise_ = 0;
  Eigen::MatrixXd h_, r_;
};

}  // namespace recruit::control
