#include "estimation/failure_filter.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "estimation/population_chain.h"

namespace recruit {

int OpenEntry(const BroadcastTransitionModel& chain, int j) {
  return chain.is_on[j] ? chain.off_target[j] : j;  // cools from its temperature
}

int StuckEntry(const BroadcastTransitionModel& chain, int j) {
  return chain.is_on[j] ? j : chain.on_target[j];  // heats from the first heating state
}

Eigen::MatrixXd AugmentedTransition(const BroadcastTransitionModel& chain, double p_on,
                                    double p_off, double q_open, double q_stuck) {
  const int m = chain.num_states();
  const Eigen::MatrixXd Aw = chain.Matrix(p_on, p_off);
  const Eigen::MatrixXd& Af = chain.interior;  // A_w(0, 0): failed units ignore broadcasts
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(3 * m, 3 * m);
  for (int j = 0; j < m; ++j) {
    const bool heated = chain.is_on[j];
    const double qo = heated ? q_open : 0, qs = heated ? q_stuck : 0;
    A.col(j).head(m) = (1 - qo - qs) * Aw.col(j);
    A(m + OpenEntry(chain, j), j) += qo;
    A(2 * m + StuckEntry(chain, j), j) += qs;
  }
  A.block(m, m, m, m) = Af;
  A.block(2 * m, 2 * m, m, m) = Af;
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
  if (!(jump_hazard >= 0 && jump_hazard <= 1)) {
    return Error{"failure filter: jump_hazard = " + std::to_string(jump_hazard) +
                 " must be in [0, 1]"};
  }
  if (!(settle_hazard >= 0 && settle_hazard <= 1)) {
    return Error{"failure filter: settle_hazard = " + std::to_string(settle_hazard) +
                 " must be in [0, 1]"};
  }
  if (!(std::isfinite(jump_fraction_std) && jump_fraction_std >= 0)) {
    return Error{"failure filter: jump_fraction_std = " + std::to_string(jump_fraction_std) +
                 " must be finite and >= 0"};
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
  A_ = Eigen::MatrixXd::Identity(3 * m_ + 1, 3 * m_ + 1);
}

void FailureKalmanFilter::Reset() {
  inner_.Reset(model_.x0, model_.P0);
  augmented_ = false;
  history_.clear();
  onset_low_ = onset_high_ = 0;
  g_low_ = g_high_ = 0;
  declarations_ = 0;
  declared_last_ = false;
  declared_class_[1] = declared_class_[2] = false;
  if (params_.open_hazard > 0 || params_.stuck_hazard > 0 || params_.scale_variance > 0) Augment();
}

void FailureKalmanFilter::Augment() {
  x_ = Eigen::VectorXd::Zero(3 * m_ + 1);
  x_.head(m_) = inner_.estimate();
  x_[3 * m_] = 1;
  P_ = Eigen::MatrixXd::Zero(3 * m_ + 1, 3 * m_ + 1);
  P_.topLeftCorner(m_, m_) = inner_.covariance();
  augmented_ = true;
}

const Eigen::VectorXd& FailureKalmanFilter::estimate() const {
  view_x_ = Eigen::VectorXd::Zero(3 * m_);
  if (augmented_) {
    view_x_ = x_.head(3 * m_);
  } else {
    view_x_.head(m_) = inner_.estimate();
  }
  return view_x_;
}

const Eigen::MatrixXd& FailureKalmanFilter::covariance() const {
  view_P_ = Eigen::MatrixXd::Zero(3 * m_, 3 * m_);
  if (augmented_) {
    view_P_ = P_.topLeftCorner(3 * m_, 3 * m_);
  } else {
    view_P_.topLeftCorner(m_, m_) = inner_.covariance();
  }
  return view_P_;
}

double FailureKalmanFilter::working_variance() const {
  if (!augmented_) return 0;
  return P_.block(m_, m_, 2 * m_, 2 * m_).sum();
}

void FailureKalmanFilter::SetOutput(const Eigen::MatrixXd& H, const Eigen::MatrixXd& R) {
  H_ = H;
  R_ = R;
  inner_.SetOutput(H, R);
}

int FailureKalmanFilter::FailEntry(int j, int to) const {
  return to * m_ + (to == 1 ? OpenEntry(model_.broadcast, j) : StuckEntry(model_.broadcast, j));
}

Eigen::MatrixXd FailureKalmanFilter::JumpQz(const Eigen::VectorXd& xq, double q, int to) const {
  const int n = 3 * m_;
  Eigen::MatrixXd J = Eigen::MatrixXd::Identity(n, n);
  for (int j = 0; j < m_; ++j) {
    J(j, j) = 1 - q;
    J(FailEntry(j, to), j) += q;
  }
  return ProcessCovarianceQz(J, xq);
}

Eigen::MatrixXd FailureKalmanFilter::JumpCovariance(int to) const {
  // A common cause (a lost connector, a burnt driver bank) takes a fraction f of the working
  // units, in proportion to each state's count: dX = f v, v = sum_j x_j (e_fail(j) - e_j).
  const int n = 3 * m_;
  const Eigen::VectorXd xq = ProjectOntoSimplex(x_.head(n), N_);
  Eigen::VectorXd v = Eigen::VectorXd::Zero(n);
  for (int j = 0; j < m_; ++j) {
    v[j] -= xq[j];
    v[FailEntry(j, to)] += xq[j];
  }
  const double sf = params_.jump_fraction_std;
  return sf * sf * v * v.transpose() + JumpQz(xq, params_.jump_hazard, to);
}

Eigen::RowVectorXd FailureKalmanFilter::OutputRow(const Eigen::MatrixXd& H) const {
  Eigen::RowVectorXd h = Eigen::RowVectorXd::Zero(3 * m_ + 1);
  h.head(m_) = x_[3 * m_] * H.row(0);
  h.segment(m_, m_) = H.row(0);
  h.segment(2 * m_, m_) = H.row(0);
  if (params_.scale_variance > 0) h[3 * m_] = H.row(0).dot(x_.head(m_));
  return h;
}

double FailureKalmanFilter::Predicted(const Eigen::MatrixXd& H) const {
  const auto h = H.row(0);
  return x_[3 * m_] * h.dot(x_.head(m_)) + h.dot(x_.segment(m_, m_)) +
         h.dot(x_.segment(2 * m_, m_));
}

void FailureKalmanFilter::UpdateCore(double y, const Eigen::MatrixXd& H, double R) {
  // Kalman update in Joseph form (r = 1), linearised in c.
  const Eigen::RowVectorXd h = OutputRow(H);
  const double s = h * P_ * h.transpose() + R;
  const Eigen::VectorXd K = P_ * h.transpose() / s;
  x_ += K * (y - Predicted(H));
  const Eigen::MatrixXd IKH = Eigen::MatrixXd::Identity(3 * m_ + 1, 3 * m_ + 1) - K * h;
  P_ = IKH * P_ * IKH.transpose() + K * R * K.transpose();
  P_ = 0.5 * (P_ + P_.transpose()).eval();
  x_.head(3 * m_).array() += (N_ - x_.head(3 * m_).sum()) / (3 * m_);  // round-off of sum = N
}

void FailureKalmanFilter::Update(double y) {
  declared_last_ = false;
  // The prior of this instant, for a replay from the onset of a change.
  History rec;
  rec.y = y;
  rec.H = H_;
  rec.R = R_(0, 0);
  if (augmented_) {
    rec.x = x_;
    rec.P = P_;
  } else {
    rec.x = Eigen::VectorXd::Zero(3 * m_ + 1);
    rec.x.head(m_) = inner_.estimate();
    rec.x[3 * m_] = 1;
    rec.P = Eigen::MatrixXd::Zero(3 * m_ + 1, 3 * m_ + 1);
    rec.P.topLeftCorner(m_, m_) = inner_.covariance();
  }
  // Innovation and its variance on the filter that runs now (read only).
  double nu, s;
  if (augmented_) {
    const Eigen::RowVectorXd h = OutputRow(H_);
    nu = y - Predicted(H_);
    s = h * P_ * h.transpose() + R_(0, 0);
  } else {
    const auto hw = H_.row(0);
    nu = y - hw.dot(inner_.estimate());
    s = hw * inner_.covariance() * hw.transpose() + R_(0, 0);
  }
  history_.push_back(std::move(rec));
  if (static_cast<int>(history_.size()) > kHistory) history_.pop_front();
  int declared_to = 0;
  if (params_.detect && s > 0) {
    const double e = nu / std::sqrt(s);
    // The onset: instants since each statistic last left 0.
    onset_low_ = g_low_ == 0 ? 0 : onset_low_ + 1;
    onset_high_ = g_high_ == 0 ? 0 : onset_high_ + 1;
    g_low_ = std::max(0.0, g_low_ - e - params_.cusum_drift);
    g_high_ = std::max(0.0, g_high_ + e - params_.cusum_drift);
    if (g_low_ > params_.cusum_threshold) declared_to = 1;   // force short: open
    if (g_high_ > params_.cusum_threshold) declared_to = 2;  // force over: stuck
  }
  if (declared_to == 0) {
    if (augmented_) {
      UpdateCore(y, H_, R_(0, 0));
    } else {
      Eigen::VectorXd yv(1);
      yv[0] = y;
      inner_.Update(yv);
    }
    return;
  }
  // A declared failure: back to the prior at the onset, the jump there, then the measurements
  // and broadcasts since, replayed.
  const int back =
      std::min(declared_to == 1 ? onset_low_ : onset_high_, static_cast<int>(history_.size()) - 1);
  g_low_ = g_high_ = 0;
  onset_low_ = onset_high_ = 0;
  ++declarations_;
  declared_last_ = true;
  declared_class_[declared_to] = true;
  augmented_ = true;
  const int first = static_cast<int>(history_.size()) - 1 - back;
  x_ = history_[first].x;
  P_ = history_[first].P;
  P_.topLeftCorner(3 * m_, 3 * m_) += JumpCovariance(declared_to);
  for (int i = first; i < static_cast<int>(history_.size()); ++i) {
    const History& r = history_[i];
    UpdateCore(r.y, r.H, r.R);
    if (i + 1 < static_cast<int>(history_.size())) PredictCore(r.p_on, r.p_off);
  }
}

void FailureKalmanFilter::PredictBroadcast(double p_on, double p_off) {
  if (!history_.empty()) {
    history_.back().p_on = p_on;
    history_.back().p_off = p_off;
  }
  if (!augmented_) {
    inner_.PredictBroadcast(p_on, p_off);
    return;
  }
  PredictCore(p_on, p_off);
}

void FailureKalmanFilter::PredictCore(double p_on, double p_off) {
  const int n = 3 * m_;
  A_.topLeftCorner(n, n) =
      AugmentedTransition(model_.broadcast, p_on, p_off, params_.open_hazard, params_.stuck_hazard);
  const auto A = A_.topLeftCorner(n, n);
  Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(n + 1, n + 1);
  if (mode_ == CovarianceMode::kExtended) {
    Q.topLeftCorner(n, n) = ProcessCovarianceQz(A, ProjectOntoSimplex(x_.head(n), N_));
  } else if (mode_ == CovarianceMode::kConservative) {
    Q.topLeftCorner(n, n) = ConservativeQz(A, N_);
  }
  if (model_.G.cols() > 0) Q.topLeftCorner(m_, m_) += model_.ProcessNoise();
  Q(n, n) = params_.scale_variance;
  if (params_.settle_hazard > 0) {
    const Eigen::VectorXd xq = ProjectOntoSimplex(x_.head(n), N_);
    for (int to : {1, 2}) {
      if (declared_class_[to]) Q.topLeftCorner(n, n) += JumpQz(xq, params_.settle_hazard, to);
    }
  }
  P_ = A_ * P_ * A_.transpose() + Q;
  x_ = A_ * x_;
}

}  // namespace recruit
