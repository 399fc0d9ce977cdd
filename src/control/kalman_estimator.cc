#include "control/kalman_estimator.h"

#include <cmath>

namespace recruit::control {

Status CheckEstimatorInputs(const estimation::FilterModel& model,
                            const std::optional<UnitForceMap>& output, double relative_noise) {
  if (Status s = model.Validate(); !s) return Error{s.error(), s.code()};
  if (model.transition != estimation::TransitionSource::kBroadcast) {
    return Error{
        "estimator: the filter model's transition must be of type \"broadcast\" (the "
        "controller drives it with p_on, p_off)"};
  }
  if (model.num_outputs() != 1) {
    return Error{"estimator: the filter model must have one output (the bundle's force), has " +
                 std::to_string(model.num_outputs())};
  }
  if (output && output->num_states() != model.num_states()) {
    return Error{"estimator: the unit force map has " + std::to_string(output->num_states()) +
                 " states, the model " + std::to_string(model.num_states())};
  }
  if (!std::isfinite(relative_noise) || relative_noise < 0) {
    return Error{"estimator: relative_noise = " + std::to_string(relative_noise) +
                 " must be finite and >= 0"};
  }
  return {};
}

Result<std::unique_ptr<KalmanOnCountEstimator>> KalmanOnCountEstimator::Create(
    const estimation::FilterModel& model, estimation::CovarianceMode mode,
    std::optional<UnitForceMap> output, double relative_noise) {
  RECRUIT_TRY(CheckEstimatorInputs(model, output, relative_noise));
  auto filter = estimation::PopulationKalmanFilter::Create(model, mode);
  if (!filter) return Error{filter.error(), filter.code()};
  return std::unique_ptr<KalmanOnCountEstimator>(new KalmanOnCountEstimator(
      model, std::move(filter).value(), std::move(output), relative_noise));
}

KalmanOnCountEstimator::KalmanOnCountEstimator(estimation::FilterModel model,
                                               estimation::PopulationKalmanFilter filter,
                                               std::optional<UnitForceMap> output,
                                               double relative_noise)
    : model_(std::move(model)),
      filter_(std::move(filter)),
      output_(std::move(output)),
      relative_noise_(relative_noise) {
  const int m = model_.num_states();
  on_mask_ = Eigen::VectorXd::Zero(m);
  for (int i = 0; i < m; ++i) on_mask_[i] = model_.broadcast.is_on[i] ? 1.0 : 0.0;
  y_.resize(1);
  h_ = model_.H;
  r_ = model_.R;
}

double KalmanOnCountEstimator::EstimatedOnVariance() const {
  // on^T P on, column by column: no temporary vector (the controller reads it every step).
  const auto& P = filter_.covariance();
  double v = 0;
  for (Eigen::Index j = 0; j < P.cols(); ++j) {
    if (on_mask_[j] != 0.0) v += on_mask_.dot(P.col(j));
  }
  return v;
}

void KalmanOnCountEstimator::Reset() { filter_.Reset(model_.x0, model_.P0); }

void KalmanOnCountEstimator::UpdateWithMeasurement(double measured_force, double tendon_length) {
  if (!std::isfinite(measured_force)) return;  // a lost sample: predict only
  if (output_ || relative_noise_ > 0) {
    if (output_ && std::isfinite(tendon_length)) {
      auto row = h_.row(0);
      output_->Forces(tendon_length, row);
    } else {
      h_ = model_.H;
    }
    const double predicted = h_.row(0).dot(filter_.estimate());
    r_(0, 0) = model_.R(0, 0) + relative_noise_ * relative_noise_ * predicted * predicted;
    filter_.SetOutput(h_, r_);
  }
  y_[0] = measured_force;
  filter_.Update(y_);
}

void KalmanOnCountEstimator::Broadcasted(const Broadcast& b) {
  // The broadcast A has at most 3 nonzeros per column: the filter's sparse prediction,
  // O(m nnz) instead of two dense m x m products (equal up to round-off).
  filter_.PredictBroadcast(b.p_on, b.p_off);
}

}  // namespace recruit::control
