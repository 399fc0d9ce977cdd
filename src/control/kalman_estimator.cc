#include "control/kalman_estimator.h"

#include <cmath>

namespace recruit::control {

Result<std::unique_ptr<KalmanOnCountEstimator>> KalmanOnCountEstimator::Create(
    const FilterModel& model, CovarianceMode mode) {
  if (Status s = model.Validate(); !s) return Error{s.error()};
  if (model.transition != TransitionSource::kBroadcast) {
    return Error{
        "estimator: the filter model's transition must be of type \"broadcast\" (the "
        "controller drives it with p_on, p_off)"};
  }
  if (model.num_outputs() != 1) {
    return Error{"estimator: the filter model must have one output (the bundle's force), has " +
                 std::to_string(model.num_outputs())};
  }
  auto filter = PopulationKalmanFilter::Create(model, mode);
  if (!filter) return Error{filter.error()};
  return std::unique_ptr<KalmanOnCountEstimator>(
      new KalmanOnCountEstimator(model, std::move(filter).value()));
}

KalmanOnCountEstimator::KalmanOnCountEstimator(FilterModel model, PopulationKalmanFilter filter)
    : model_(std::move(model)), filter_(std::move(filter)) {
  const int m = model_.num_states();
  on_mask_ = Eigen::VectorXd::Zero(m);
  for (int i = 0; i < m; ++i) on_mask_[i] = model_.broadcast.is_on[i] ? 1.0 : 0.0;
  y_.resize(1);
}

void KalmanOnCountEstimator::Reset() { filter_.Reset(model_.x0, model_.P0); }

void KalmanOnCountEstimator::Observe(double measured_force) {
  if (!std::isfinite(measured_force)) return;  // a lost sample: predict only
  y_[0] = measured_force;
  filter_.Update(y_);
}

void KalmanOnCountEstimator::Broadcasted(const Broadcast& b) {
  // The broadcast A has at most 3 nonzeros per column: the filter's sparse prediction,
  // O(m nnz) instead of two dense m x m products (equal up to round-off).
  filter_.PredictBroadcast(b.p_on, b.p_off);
}

}  // namespace recruit::control
