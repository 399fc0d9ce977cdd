#include "control/failure_estimator.h"

#include <cmath>
#include <string>

#include "control/kalman_estimator.h"

namespace recruit::control {

Result<std::unique_ptr<FailureOnCountEstimator>> FailureOnCountEstimator::Create(
    const estimation::FilterModel& model, estimation::CovarianceMode mode,
    const estimation::FailureFilterParams& params, std::optional<UnitForceMap> output,
    double relative_noise) {
  RECRUIT_TRY(CheckEstimatorInputs(model, output, relative_noise));
  auto filter = estimation::FailureKalmanFilter::Create(model, mode, params);
  if (!filter) return filter.failure();
  return std::unique_ptr<FailureOnCountEstimator>(new FailureOnCountEstimator(
      model, std::move(filter).value(), std::move(output), relative_noise));
}

FailureOnCountEstimator::FailureOnCountEstimator(estimation::FilterModel model,
                                                 estimation::FailureKalmanFilter filter,
                                                 std::optional<UnitForceMap> output,
                                                 double relative_noise)
    : model_(std::move(model)),
      filter_(std::move(filter)),
      output_(std::move(output)),
      relative_noise_(relative_noise) {
  const int m = model_.num_states();
  on_mask_ = Eigen::VectorXd::Zero(3 * m);
  for (int i = 0; i < m; ++i) on_mask_[i] = model_.broadcast.is_on[i] ? 1.0 : 0.0;
  on_mask_.tail(m).setOnes();  // stuck units are heated
  on_mask_w_ = on_mask_.head(m);
  h_ = model_.H;
  r_ = model_.R;
}

double FailureOnCountEstimator::EstimatedOn() const {
  if (!filter_.augmented()) {
    // The paper's filter, summed as KalmanOnCountEstimator sums it (bit-identical).
    return on_mask_w_.dot(filter_.working_filter().estimate());
  }
  return on_mask_.dot(filter_.estimate());
}

double FailureOnCountEstimator::EstimatedOnVariance() const {
  if (!filter_.augmented()) {
    const auto& P = filter_.working_filter().covariance();
    double v = 0;
    for (Eigen::Index j = 0; j < P.cols(); ++j) {
      if (on_mask_w_[j] != 0.0) v += on_mask_w_.dot(P.col(j));
    }
    return v;
  }
  return on_mask_.dot(filter_.covariance() * on_mask_);
}

std::vector<std::string> FailureOnCountEstimator::StateNames() const {
  std::vector<std::string> n = model_.state_names;
  for (const std::string& s : model_.state_names) n.push_back("open:" + s);
  for (const std::string& s : model_.state_names) n.push_back("stuck:" + s);
  return n;
}

std::vector<bool> FailureOnCountEstimator::OnStates() const {
  std::vector<bool> on = model_.broadcast.is_on;
  on.insert(on.end(), model_.num_states(), false);
  on.insert(on.end(), model_.num_states(), true);
  return on;
}

std::optional<FailureEstimate> FailureOnCountEstimator::Failures() const {
  FailureEstimate f;
  f.open = filter_.open();
  f.stuck = filter_.stuck();
  f.working = filter_.working();
  f.working_variance = filter_.working_variance();
  f.declarations = filter_.declarations();
  f.declared = filter_.declared_last();
  f.force_scale = filter_.force_scale();
  f.suspicion = filter_.suspicion();
  return f;
}

void FailureOnCountEstimator::UpdateWithMeasurement(double measured_force, double tendon_length) {
  if (!std::isfinite(measured_force)) {  // a lost sample: predict only
    filter_.NoMeasurement();
    return;
  }
  if (output_ || relative_noise_ > 0) {
    // As KalmanOnCountEstimator: H at the measured length, R growing with the predicted force.
    if (output_ && std::isfinite(tendon_length)) {
      auto row = h_.row(0);
      output_->Forces(tendon_length, row);
    } else {
      h_ = model_.H;
    }
    const int m = model_.num_states();
    double predicted;
    if (filter_.augmented()) {
      const Eigen::VectorXd& e = filter_.estimate();
      predicted = h_.row(0).dot(e.head(m) + e.segment(m, m) + e.tail(m));
    } else {
      predicted = h_.row(0).dot(filter_.working_filter().estimate());
    }
    r_(0, 0) = model_.R(0, 0) + relative_noise_ * relative_noise_ * predicted * predicted;
    filter_.SetOutput(h_, r_);
  }
  filter_.Update(measured_force);
}

}  // namespace recruit::control
