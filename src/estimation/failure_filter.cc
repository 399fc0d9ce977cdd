#include "estimation/failure_filter.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "estimation/population_chain.h"

namespace recruit {

Eigen::MatrixXd AugmentedTransition(const BroadcastTransitionModel& chain, double p_on,
                                    double p_off, double q_open, double q_stuck) {
  const int m = chain.num_states();
  const Eigen::MatrixXd Aw = chain.Matrix(p_on, p_off);
  Eigen::MatrixXd A = Eigen::MatrixXd::Identity(m + 2, m + 2);
  for (int j = 0; j < m; ++j) {
    const bool heated = chain.is_on[j];
    const double qo = heated ? q_open : 0, qs = heated ? q_stuck : 0;
    A.col(j).head(m) = (1 - qo - qs) * Aw.col(j);
    A(m, j) = qo;
    A(m + 1, j) = qs;
  }
  return A;
}

Status FailureFilterParams::Validate() const {
  auto prob = [](double v) { return std::isfinite(v) && v >= 0 && v <= 1; };
  if (!prob(open_hazard) || !prob(stuck_hazard) || open_hazard + stuck_hazard > 1) {
    return Error{"failure filter: open_hazard = " + std::to_string(open_hazard) +
                 " and stuck_hazard = " + std::to_string(stuck_hazard) +
                 " must be probabilities per control period adding to at most 1"};
  }
  if (!(std::isfinite(cusum_drift) && cusum_drift >= 0)) {
    return Error{"failure filter: cusum_drift = " + std::to_string(cusum_drift) +
                 " must be finite and >= 0"};
  }
  if (!(std::isfinite(cusum_threshold) && cusum_threshold > 0)) {
    return Error{"failure filter: cusum_threshold = " + std::to_string(cusum_threshold) +
                 " must be finite and > 0"};
  }
  if (!(jump_hazard > 0 && jump_hazard <= 1)) {
    return Error{"failure filter: jump_hazard = " + std::to_string(jump_hazard) +
                 " must be in (0, 1]"};
  }
  if (!(std::isfinite(scale_variance) && scale_variance >= 0)) {
    return Error{"failure filter: scale_variance = " + std::to_string(scale_variance) +
                 " must be finite and >= 0"};
  }
  return Status::Ok();
}

Result<FailureKalmanFilter> FailureKalmanFilter::Create(const FilterModel& model,
                                                        CovarianceMode mode,
                                                        const FailureFilterParams& params) {
  if (Status s = params.Validate(); !s) return Error{s.error()};
  if (Status s = model.Validate(); !s) return Error{s.error()};
  if (model.transition != TransitionSource::kBroadcast || model.num_outputs() != 1) {
    return Error{"failure filter: the model must be a broadcast chain with one output"};
  }
  auto inner = PopulationKalmanFilter::Create(model, mode);
  if (!inner) return Error{inner.error()};
  FailureKalmanFilter f(model, mode, params, std::move(inner).value());
  f.Reset();
  return f;
}

FailureKalmanFilter::FailureKalmanFilter(FilterModel model, CovarianceMode mode,
                                         FailureFilterParams params, PopulationKalmanFilter inner)
    : model_(std::move(model)), mode_(mode), params_(params), inner_(std::move(inner)) {
  m_ = model_.num_states();
  N_ = static_cast<double>(model_.N);
  H_ = model_.H;
  R_ = model_.R;
  model_.x0.maxCoeff(&cold_);  // the belief units start in: off and settled
  double best = -1;
  for (int j = 0; j < m_; ++j) {
    if (model_.broadcast.is_on[j] && model_.H(0, j) > best) best = model_.H(0, j), hot_ = j;
  }
  A_ = Eigen::MatrixXd::Identity(m_ + 3, m_ + 3);
}

void FailureKalmanFilter::Reset() {
  inner_.Reset(model_.x0, model_.P0);
  augmented_ = false;
  g_low_ = g_high_ = 0;
  declarations_ = 0;
  declared_last_ = false;
  if (params_.open_hazard > 0 || params_.stuck_hazard > 0 || params_.scale_variance > 0) Augment();
}

void FailureKalmanFilter::Augment() {
  x_ = Eigen::VectorXd::Zero(m_ + 3);
  x_.head(m_) = inner_.estimate();
  x_[m_ + 2] = 1;
  P_ = Eigen::MatrixXd::Zero(m_ + 3, m_ + 3);
  P_.topLeftCorner(m_, m_) = inner_.covariance();
  augmented_ = true;
}

const Eigen::VectorXd& FailureKalmanFilter::estimate() const {
  view_x_ = Eigen::VectorXd::Zero(m_ + 2);
  if (augmented_) {
    view_x_ = x_.head(m_ + 2);
  } else {
    view_x_.head(m_) = inner_.estimate();
  }
  return view_x_;
}

const Eigen::MatrixXd& FailureKalmanFilter::covariance() const {
  view_P_ = Eigen::MatrixXd::Zero(m_ + 2, m_ + 2);
  if (augmented_) {
    view_P_ = P_.topLeftCorner(m_ + 2, m_ + 2);
  } else {
    view_P_.topLeftCorner(m_, m_) = inner_.covariance();
  }
  return view_P_;
}

double FailureKalmanFilter::working_variance() const {
  if (!augmented_) return 0;
  return P_(m_, m_) + P_(m_ + 1, m_ + 1) + 2 * P_(m_, m_ + 1);
}

void FailureKalmanFilter::SetOutput(const Eigen::MatrixXd& H, const Eigen::MatrixXd& R) {
  H_ = H;
  R_ = R;
  inner_.SetOutput(H, R);
}

Eigen::MatrixXd FailureKalmanFilter::JumpQz(const Eigen::VectorXd& x, double q, int to) const {
  const int n = m_ + 2;
  Eigen::MatrixXd J = Eigen::MatrixXd::Identity(n, n);
  for (int j = 0; j < m_; ++j) {
    J(j, j) = 1 - q;
    J(to, j) = q;
  }
  const Eigen::VectorXd xq = ProjectOntoSimplex(x.head(n), N_);
  return ProcessCovarianceQz(J, xq);
}

void FailureKalmanFilter::Update(double y) {
  declared_last_ = false;
  // Innovation and its variance on the filter that runs now (read only).
  Eigen::RowVectorXd h;
  if (augmented_) {
    h = Eigen::RowVectorXd::Zero(m_ + 3);
    const double c = x_[m_ + 2];
    h.head(m_) = c * H_.row(0);
    h[m_] = H_(0, cold_);
    h[m_ + 1] = H_(0, hot_);
    if (params_.scale_variance > 0) h[m_ + 2] = H_.row(0).dot(x_.head(m_));
  }
  auto innovation = [&](double* nu, double* s) {
    if (augmented_) {
      const double c = x_[m_ + 2];
      *nu = y - (c * H_.row(0).dot(x_.head(m_)) + h[m_] * x_[m_] + h[m_ + 1] * x_[m_ + 1]);
      *s = h * P_ * h.transpose() + R_(0, 0);
    } else {
      const auto hw = H_.row(0);
      *nu = y - hw.dot(inner_.estimate());
      *s = hw * inner_.covariance() * hw.transpose() + R_(0, 0);
    }
  };
  double nu, s;
  innovation(&nu, &s);
  int declared_to = -1;
  if (params_.detect && s > 0) {
    const double e = nu / std::sqrt(s);
    g_low_ = std::max(0.0, g_low_ - e - params_.cusum_drift);
    g_high_ = std::max(0.0, g_high_ + e - params_.cusum_drift);
    if (g_low_ > params_.cusum_threshold) declared_to = m_;       // force short: open
    if (g_high_ > params_.cusum_threshold) declared_to = m_ + 1;  // force over: stuck
  }
  if (declared_to < 0 && !augmented_) {
    Eigen::VectorXd yv(1);
    yv[0] = y;
    inner_.Update(yv);
    return;
  }
  if (declared_to >= 0) {
    g_low_ = g_high_ = 0;
    ++declarations_;
    declared_last_ = true;
    if (!augmented_) {
      Augment();
      h = Eigen::RowVectorXd::Zero(m_ + 3);
      h.head(m_) = H_.row(0);
      h[m_] = H_(0, cold_);
      h[m_ + 1] = H_(0, hot_);
    }
    P_.topLeftCorner(m_ + 2, m_ + 2) += JumpQz(x_, params_.jump_hazard, declared_to);
    innovation(&nu, &s);
  }
  // Kalman update in Joseph form (r = 1).
  const Eigen::VectorXd u = P_ * h.transpose();
  const Eigen::VectorXd K = u / s;
  x_ += K * nu;
  const Eigen::MatrixXd IKH = Eigen::MatrixXd::Identity(m_ + 3, m_ + 3) - K * h;
  P_ = IKH * P_ * IKH.transpose() + K * R_(0, 0) * K.transpose();
  P_ = 0.5 * (P_ + P_.transpose()).eval();
  x_.head(m_ + 2).array() += (N_ - x_.head(m_ + 2).sum()) / (m_ + 2);  // round-off of sum = N
}

void FailureKalmanFilter::FillAugmentedA(double p_on, double p_off) {
  A_.setIdentity();
  A_.topLeftCorner(m_ + 2, m_ + 2) =
      AugmentedTransition(model_.broadcast, p_on, p_off, params_.open_hazard, params_.stuck_hazard);
}

void FailureKalmanFilter::PredictBroadcast(double p_on, double p_off) {
  if (!augmented_) {
    inner_.PredictBroadcast(p_on, p_off);
    return;
  }
  FillAugmentedA(p_on, p_off);
  const int n = m_ + 2;
  const auto A = A_.topLeftCorner(n, n);
  Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(m_ + 3, m_ + 3);
  if (mode_ == CovarianceMode::kExtended) {
    Q.topLeftCorner(n, n) = ProcessCovarianceQz(A, ProjectOntoSimplex(x_.head(n), N_));
  } else if (mode_ == CovarianceMode::kConservative) {
    Q.topLeftCorner(n, n) = ConservativeQz(A, N_);
  }
  if (model_.G.cols() > 0) Q.topLeftCorner(m_, m_) += model_.ProcessNoise();
  Q(m_ + 2, m_ + 2) = params_.scale_variance;
  P_ = A_ * P_ * A_.transpose() + Q;
  x_ = A_ * x_;
}

}  // namespace recruit
