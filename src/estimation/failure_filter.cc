#include "estimation/failure_filter.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "estimation/population_chain.h"

namespace recruit::estimation {

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

FailureGlr::FailureGlr(const BroadcastTransitionModel& chain, int window)
    : m_(chain.num_states()), window_(window) {
  for (int j = 0; j < m_; ++j) {
    entry_[1].push_back(m_ + OpenEntry(chain, j));
    entry_[2].push_back(2 * m_ + StuckEntry(chain, j));
  }
  truth_ = Eigen::MatrixXd::Zero(3 * m_, 2 * window_);
  filt_ = Eigen::MatrixXd::Zero(3 * m_, 2 * window_);
  d_ = Eigen::VectorXd::Zero(2 * window_);
  C_ = Eigen::VectorXd::Zero(2 * window_);
  age_.assign(2 * window_, -1);
}

void FailureGlr::Clear() {
  std::fill(age_.begin(), age_.end(), -1);
  next_ = 0;
}

void FailureGlr::Open(const Eigen::VectorXd& x_prior) {
  const Eigen::VectorXd w = x_prior.head(m_).cwiseMax(0.0);
  const double W = w.sum();
  for (int to : {1, 2}) {
    const int col = (to - 1) * window_ + next_;
    truth_.col(col).setZero();
    filt_.col(col).setZero();
    d_[col] = C_[col] = 0;
    age_[col] = -1;
    if (!(W > 0)) continue;
    for (int j = 0; j < m_; ++j) {
      truth_(j, col) -= w[j] / W;
      truth_(entry_[to][j], col) += w[j] / W;
    }
    age_[col] = 0;
  }
  next_ = (next_ + 1) % window_;
}

void FailureGlr::Update(double nu, double s, const Eigen::RowVectorXd& h,
                        const Eigen::VectorXd& K) {
  const Eigen::RowVectorXd rho = h * (truth_ - filt_);
  d_ += rho.transpose() * (nu / s);
  C_ += rho.transpose().cwiseAbs2() / s;
  filt_ += K * rho;
}

void FailureGlr::Predict(const Eigen::MatrixXd& A) {
  truth_ = A * truth_;
  filt_ = A * filt_;
  for (int& a : age_) a += a >= 0 ? 1 : 0;
}

FailureGlr::Best FailureGlr::Hypothesis(int to, int age) const {
  Best b;
  for (int col = (to - 1) * window_; col < to * window_; ++col) {
    if (age_[col] != age || !(C_[col] > 0)) continue;
    b.to = to;
    b.age = age;
    b.count = d_[col] / C_[col];
    b.variance = 1 / C_[col];
    b.llr = d_[col] > 0 ? d_[col] * d_[col] / (2 * C_[col]) : 0.0;
    b.deviation = truth_.col(col) - filt_.col(col);
  }
  return b;
}

FailureGlr::Best FailureGlr::ForCount(int to, double k) const {
  Best b;
  double best = -std::numeric_limits<double>::infinity();
  for (int col = (to - 1) * window_; col < to * window_; ++col) {
    if (age_[col] < 0) continue;
    const double l = k * d_[col] - 0.5 * k * k * C_[col];
    if (!(l > best)) continue;
    best = l;
    b.to = to;
    b.age = age_[col];
    b.count = k;
    b.variance = C_[col] > 0 ? 1 / C_[col] : 0.0;
    b.llr = l;
    b.deviation = truth_.col(col) - filt_.col(col);
  }
  return b;
}

FailureGlr::Best FailureGlr::Strongest(double max_std) const {
  Best b;
  const double min_information = 1 / (max_std * max_std);
  for (int col = 0; col < 2 * window_; ++col) {
    if (age_[col] < 0 || !(C_[col] >= min_information) || !(d_[col] > 0)) continue;
    const double llr = d_[col] * d_[col] / (2 * C_[col]);
    if (llr <= b.llr) continue;
    b.to = col < window_ ? 1 : 2;
    b.age = age_[col];
    b.count = d_[col] / C_[col];
    b.variance = 1 / C_[col];
    b.llr = llr;
    b.deviation = truth_.col(col) - filt_.col(col);
  }
  return b;
}

Status FailureFilterParams::Validate() const {
  auto prob = [](double v) { return std::isfinite(v) && v >= 0 && v <= 1; };
  if (!prob(open_hazard) || !prob(stuck_hazard) || open_hazard + stuck_hazard > 1) {
    return Error{"failure filter: open_hazard = " + std::to_string(open_hazard) +
                 " and stuck_hazard = " + std::to_string(stuck_hazard) +
                 " must be probabilities per control period adding to at most 1"};
  }
  if (!(glr_window >= 1 && glr_window <= 1000)) {
    return Error{"failure filter: glr_window = " + std::to_string(glr_window) +
                 " must be 1..1000 control instants"};
  }
  if (!(std::isfinite(glr_threshold) && glr_threshold > 0)) {
    return Error{"failure filter: glr_threshold = " + std::to_string(glr_threshold) +
                 " must be finite and > 0"};
  }
  if (!(std::isfinite(glr_max_std) && glr_max_std > 0)) {
    return Error{"failure filter: glr_max_std = " + std::to_string(glr_max_std) +
                 " must be finite and > 0 (units)"};
  }
  if (!(std::isfinite(glr_min_count) && glr_min_count >= 0)) {
    return Error{"failure filter: glr_min_count = " + std::to_string(glr_min_count) +
                 " must be finite and >= 0"};
  }
  if (!(settle_hazard >= 0 && settle_hazard <= 1)) {
    return Error{"failure filter: settle_hazard = " + std::to_string(settle_hazard) +
                 " must be in [0, 1]"};
  }
  if (!(std::isfinite(scale_initial_variance) && scale_initial_variance >= 0)) {
    return Error{"failure filter: scale_initial_variance = " +
                 std::to_string(scale_initial_variance) + " must be finite and >= 0"};
  }
  if (!(std::isfinite(census_min_jump) && census_min_jump >= 0) ||
      !(std::isfinite(census_jump_sigma) && census_jump_sigma >= 0)) {
    return Error{"failure filter: census_min_jump = " + std::to_string(census_min_jump) +
                 " and census_jump_sigma = " + std::to_string(census_jump_sigma) +
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
  if (Status s = params.Validate(); !s) return s.failure();
  if (Status s = model.Validate(); !s) return s.failure();
  if (model.transition != TransitionSource::kBroadcast || model.num_outputs() != 1) {
    return Error{"failure filter: the model must be a broadcast chain with one output"};
  }
  auto inner = PopulationKalmanFilter::Create(model, mode);
  if (!inner) return inner.failure();
  FailureKalmanFilter f(model, mode, params, std::move(inner).value());
  f.Reset();
  return f;
}

FailureKalmanFilter::FailureKalmanFilter(FilterModel model, CovarianceMode mode,
                                         FailureFilterParams params, PopulationKalmanFilter inner)
    : model_(std::move(model)),
      mode_(mode),
      params_(params),
      inner_(std::move(inner)),
      glr_(model_.broadcast, params.glr_window) {
  m_ = model_.num_states();
  N_ = static_cast<double>(model_.N);
  H_ = model_.H;
  R_ = model_.R;
  if (model_.has_transit_noise()) transit_ = model_.TransitWeights();
  A_ = Eigen::MatrixXd::Identity(3 * m_ + 1, 3 * m_ + 1);
}

void FailureKalmanFilter::Reset() {
  inner_.Reset(model_.x0, model_.P0);
  augmented_ = false;
  glr_.Clear();
  declarations_ = 0;
  declared_last_ = false;
  census_declared_ = false;
  censuses_ = 0;
  suspicion_ = 0;
  last_declared_ = {};
  declared_class_[1] = declared_class_[2] = false;
  if (params_.open_hazard > 0 || params_.stuck_hazard > 0 || params_.scale_variance > 0) Augment();
}

void FailureKalmanFilter::Augment() {
  x_ = Eigen::VectorXd::Zero(3 * m_ + 1);
  x_.head(m_) = inner_.estimate();
  x_[3 * m_] = 1;
  P_ = Eigen::MatrixXd::Zero(3 * m_ + 1, 3 * m_ + 1);
  P_.topLeftCorner(m_, m_) = inner_.covariance();
  if (params_.scale_variance > 0) P_(3 * m_, 3 * m_) = params_.scale_initial_variance;
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

double FailureKalmanFilter::OutputNoise() const {
  if (transit_.size() == 0) return R_(0, 0);
  double n = 0;
  if (!augmented_) {
    n = inner_.TransitCount();
  } else {
    // Working, open and stuck units alike are in transit while their wires heat or cool.
    for (int b = 0; b < 3; ++b) {
      for (int j = 0; j < m_; ++j) {
        if (x_[b * m_ + j] > 0.0) n += transit_[j] * x_[b * m_ + j];
      }
    }
  }
  const auto [rt, rt2] = model_.ScalarTransitNoise();
  return R_(0, 0) + (n * rt + (n * n) * rt2);
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

void FailureKalmanFilter::Declare(const FailureGlr::Best& best) {
  if (!augmented_) Augment();
  const int n = 3 * m_;
  // The estimate moves by k^ (truth - estimate) per lost unit; its covariance grows by Var(k^)
  // along that direction and by the spread of which states k^ independent failures leave from.
  x_.head(n) += best.count * best.deviation;
  const Eigen::VectorXd xq = ProjectOntoSimplex(x_.head(n), N_);
  const double W = xq.head(m_).sum();
  const double q = W > 0 ? std::min(1.0, best.count / W) : 0.0;
  P_.topLeftCorner(n, n) +=
      best.variance * best.deviation * best.deviation.transpose() + JumpQz(xq, q, best.to);
  ++declarations_;
  declared_last_ = true;
  declared_class_[best.to] = true;
  last_declared_ = best;
  glr_.Clear();
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
  // Linearised in c: the row is the output's derivative, the innovation its exact value.
  last_gain_ = ScalarUpdate(OutputRow(H), y - Predicted(H), R);
  x_.head(3 * m_).array() += (N_ - x_.head(3 * m_).sum()) / (3 * m_);  // round-off of sum = N
}

void FailureKalmanFilter::Update(double y) {
  declared_last_ = census_declared_;
  census_declared_ = false;
  suspicion_ = 0;
  const int n = 3 * m_;
  // The innovation and its variance on the filter that runs now, and the prior for the GLR.
  double nu, s;
  if (augmented_) {
    const Eigen::RowVectorXd h = OutputRow(H_);
    nu = y - Predicted(H_);
    s = h * P_ * h.transpose() + OutputNoise();
  } else {
    const auto hw = H_.row(0);
    nu = y - hw.dot(inner_.estimate());
    s = hw * inner_.covariance() * hw.transpose() + OutputNoise();
  }
  const bool test = params_.detect && s > 0 && std::isfinite(nu);
  if (test) glr_.Open(estimate());
  Eigen::VectorXd K = Eigen::VectorXd::Zero(n);
  if (augmented_) {
    UpdateCore(y, H_, OutputNoise());
    K = last_gain_.head(n);
  } else {
    Eigen::VectorXd yv(1);
    yv[0] = y;
    inner_.Update(yv);
    K.head(m_) = inner_.gain().col(0);
  }
  if (!test) return;
  // The true force's row on the 3m states: every unit pulls, the working ones scaled by c.
  Eigen::RowVectorXd h(n);
  h << force_scale() * H_.row(0), H_.row(0), H_.row(0);
  glr_.Update(nu, s, h, K);
  const FailureGlr::Best best = glr_.Strongest(params_.glr_max_std);
  suspicion_ = best.llr;
  if (best.to != 0 && best.llr > params_.glr_threshold && best.count >= params_.glr_min_count) {
    Declare(best);
    suspicion_ = 0;
  }
}

Eigen::VectorXd FailureKalmanFilter::ScalarUpdate(const Eigen::RowVectorXd& h, double innovation,
                                                  double r) {
  // Kalman update in Joseph form, one output.
  const double s = h * P_ * h.transpose() + r;
  const Eigen::VectorXd K = P_ * h.transpose() / s;
  x_ += K * innovation;
  const Eigen::MatrixXd IKH = Eigen::MatrixXd::Identity(x_.size(), x_.size()) - K * h;
  P_ = IKH * P_ * IKH.transpose() + K * r * K.transpose();
  P_ = 0.5 * (P_ + P_.transpose()).eval();
  return K;
}

void FailureKalmanFilter::AddCensusJump(int to, double k) {
  const int n = 3 * m_;
  Eigen::VectorXd g = Eigen::VectorXd::Zero(n);
  const Eigen::VectorXd xq = ProjectOntoSimplex(x_.head(n), N_);
  if (k > 0) {
    // Units lost: the onset and the filter's response that best explain the innovations for
    // that count; without a hypothesis, lost now from the working states in proportion.
    const FailureGlr::Best b = params_.detect ? glr_.ForCount(to, k) : FailureGlr::Best{};
    if (b.to != 0) {
      g = b.deviation;
    } else {
      const double W = xq.head(m_).sum();
      for (int j = 0; W > 0 && j < m_; ++j) {
        g[j] -= xq[j] / W;
        g[FailEntry(j, to)] += xq[j] / W;
      }
    }
    const double W = xq.head(m_).sum();
    if (W > 0) P_.topLeftCorner(n, n) += JumpQz(xq, std::min(1.0, k / W), to);
  } else {
    // Fewer lost than declared: units of the class back to the same thermal state of the chain.
    const Eigen::VectorXd c = xq.segment(to * m_, m_);
    const double C = c.sum();
    for (int j = 0; C > 0 && j < m_; ++j) {
      g[to * m_ + j] -= c[j] / C;
      g[j] += c[j] / C;
    }
  }
  P_.topLeftCorner(n, n) += kCensusJumpVariance * g * g.transpose();
}

void FailureKalmanFilter::UpdateCensus(double conducting, double stuck_count, double variance) {
  census_declared_ = false;
  if (!(variance > 0) || !std::isfinite(conducting) || !std::isfinite(stuck_count)) return;
  ++censuses_;
  const int n = 3 * m_;
  // Residuals in units: units newly open (conducting fewer than estimated), newly stuck.
  const double e[3] = {0, N_ - open() - stuck() - conducting, stuck_count - stuck()};
  bool jump[3] = {false, false, false};
  for (int to : {1, 2}) {
    const double var = augmented_ ? P_.block(to * m_, to * m_, m_, m_).sum() : 0.0;
    jump[to] = std::abs(e[to]) > params_.census_min_jump &&
               std::abs(e[to]) > params_.census_jump_sigma * std::sqrt(var + variance);
  }
  if (!augmented_ && !jump[1] && !jump[2]) {
    glr_.Clear();  // the census confirms the no-loss filter: nothing moves
    return;
  }
  if (!augmented_) Augment();
  for (int to : {1, 2}) {
    if (jump[to]) AddCensusJump(to, e[to]);
  }
  Eigen::RowVectorXd h1 = Eigen::RowVectorXd::Zero(n + 1), h2 = Eigen::RowVectorXd::Zero(n + 1);
  h1.head(m_).setOnes();
  h1.segment(2 * m_, m_).setOnes();
  h2.segment(2 * m_, m_).setOnes();
  ScalarUpdate(h1, conducting - h1.dot(x_), variance);
  ScalarUpdate(h2, stuck_count - h2.dot(x_), variance);
  x_.head(n).array() += (N_ - x_.head(n).sum()) / n;  // round-off of sum = N
  glr_.Clear();
  if (jump[1] || jump[2]) {
    ++declarations_;
    census_declared_ = true;
    for (int to : {1, 2}) declared_class_[to] = declared_class_[to] || (jump[to] && e[to] > 0);
  }
}

void FailureKalmanFilter::PredictBroadcast(double p_on, double p_off) {
  const int n = 3 * m_;
  A_.topLeftCorner(n, n) =
      AugmentedTransition(model_.broadcast, p_on, p_off, params_.open_hazard, params_.stuck_hazard);
  if (params_.detect) glr_.Predict(A_.topLeftCorner(n, n));
  if (!augmented_) {
    inner_.PredictBroadcast(p_on, p_off);
    return;
  }
  PredictCore();
}

void FailureKalmanFilter::PredictCore() {
  const int n = 3 * m_;
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

}  // namespace recruit::estimation
