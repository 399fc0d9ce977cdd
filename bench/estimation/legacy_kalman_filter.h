// The PopulationKalmanFilterT of commit f33d0b3 (before the symmetric / sparse-A work), kept
// verbatim apart from its name as the side-by-side baseline of bench_estimation: the ratio of
// the current filter to this one is measured in the same run (docs/benchmarks.md). Not for use
// outside the benchmark.
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <functional>
#include <string>

#include "common/result.h"
#include "estimation/filter_model.h"
#include "estimation/population_chain.h"
#include "estimation/population_kalman_filter.h"

namespace recruit {
namespace legacy {

template <int M, int R>
class LegacyKalmanFilterT {
 public:
  using Vec = Eigen::Matrix<double, M, 1>;        // counts per state
  using Mat = Eigen::Matrix<double, M, M>;        // A, P
  using OutVec = Eigen::Matrix<double, R, 1>;     // y
  using OutMat = Eigen::Matrix<double, R, R>;     // R, S
  using OutputMat = Eigen::Matrix<double, R, M>;  // H
  using GainMat = Eigen::Matrix<double, M, R>;    // K, P H^T

  // Validates the model and the initial belief: x0 (m entries, finite, summing to N within
  // 1e-9 N) and P0 (m x m, symmetric PSD). P0 is projected onto 1^T P0 = 0 (the total is
  // known). The model's sizes must equal M and R unless they are Eigen::Dynamic.
  static Result<LegacyKalmanFilterT> Create(const estimation::FilterModel& model,
                                            estimation::CovarianceMode mode,
                                            const Eigen::VectorXd& x0, const Eigen::MatrixXd& P0);
  // With the model's own initial belief (model.x0, model.P0).
  static Result<LegacyKalmanFilterT> Create(const estimation::FilterModel& model,
                                            estimation::CovarianceMode mode) {
    return Create(model, mode, model.x0, model.P0);
  }

  // Time update with the transition A(t) (eqs. 16, 22/27). A must be column-stochastic (the
  // caller validates it, or uses PredictChecked). A step without a measurement is Predict alone.
  void Predict(const Mat& A);
  // Measurement update with y(t) (eqs. 15, 17, 19, 20 in Joseph form).
  void Update(const OutVec& y);

  // Predict / Update after checking the input (sizes, finite, column-stochastic).
  Status PredictChecked(const Eigen::MatrixXd& A);
  Status UpdateChecked(const Eigen::VectorXd& y);

  // Replaces the belief (no checks beyond the projections).
  void Reset(const Vec& x0, const Mat& P0) {
    x_ = x0;
    P_ = P0;
    Reproject();
  }

  const Vec& estimate() const { return x_; }           // X^, counts per state, sums to N
  const Mat& covariance() const { return P_; }         // P
  const OutVec& innovation() const { return innov_; }  // y - H X^(t|t-1) of the last Update
  const GainMat& gain() const { return K_; }           // K of the last Update
  estimation::CovarianceMode mode() const { return mode_; }
  double population() const { return N_; }
  int num_states() const { return static_cast<int>(x_.size()); }
  int num_outputs() const { return static_cast<int>(H_.rows()); }
  const OutputMat& H() const { return H_; }

 private:
  LegacyKalmanFilterT() = default;
  void Reproject();

  estimation::CovarianceMode mode_ = estimation::CovarianceMode::kExtended;
  double N_ = 0.0;
  OutputMat H_;
  OutMat R_;
  Mat GQG_;  // G Qw G^T, precomputed
  bool has_process_noise_ = false;
  // State.
  Vec x_;
  Mat P_;
  // Workspaces (sized at Create so that Predict / Update do not allocate).
  Vec xq_, ax_, tmp_, rowsum_;
  Mat M_, AM_;
  GainMat U_, K_, KS_;
  OutMat S_;
  OutVec innov_;
  Eigen::Matrix<double, R, M> Kt_;
  Eigen::LLT<OutMat> llt_;
};

// ---------------------------------------------------------------------------------------------
// Implementation.

namespace legacy_detail {

// Euclidean projection onto {n_i >= 0, sum n_i = N} into `out`, `work` a scratch vector of the
// same size (no allocation for fixed sizes).
template <class V>
void ProjectOntoSimplexInto(const V& x, double N, V& out, V& work) {
  if ((x.array() >= 0.0).all()) {  // feasible: the filter keeps sum x = N exactly
    out = x;
    return;
  }
  work = x;
  std::sort(work.data(), work.data() + work.size(), std::greater<double>());
  double cumsum = 0.0, theta = 0.0;
  for (Eigen::Index k = 0; k < work.size(); ++k) {
    cumsum += work(k);
    const double t = (cumsum - N) / static_cast<double>(k + 1);
    if (work(k) - t > 0.0) theta = t;
  }
  out = (x.array() - theta).max(0.0).matrix();
}

}  // namespace legacy_detail

template <int M, int R>
Result<LegacyKalmanFilterT<M, R>> LegacyKalmanFilterT<M, R>::Create(
    const estimation::FilterModel& model, estimation::CovarianceMode mode,
    const Eigen::VectorXd& x0, const Eigen::MatrixXd& P0) {
  if (Status s = model.Validate(); !s.ok()) return Error{s.error()};
  const int m = model.num_states();
  const int r = model.num_outputs();
  if (M != Eigen::Dynamic && m != M) {
    return Error{"Kalman filter: this fixed-size filter is for m = " + std::to_string(M) +
                 " states, the model has " + std::to_string(m)};
  }
  if (R != Eigen::Dynamic && r != R) {
    return Error{"Kalman filter: this fixed-size filter is for r = " + std::to_string(R) +
                 " outputs, the model has " + std::to_string(r)};
  }
  const double N = static_cast<double>(model.N);
  if (x0.size() != m || !x0.allFinite()) {
    return Error{"Kalman filter: x0 must have " + std::to_string(m) + " finite entries"};
  }
  if (std::abs(x0.sum() - N) > 1e-9 * N) {
    return Error{"Kalman filter: x0 must sum to N = " + std::to_string(model.N) + ", sums to " +
                 std::to_string(x0.sum())};
  }
  if (P0.rows() != m || P0.cols() != m || !P0.allFinite()) {
    return Error{"Kalman filter: P0 must be a finite " + std::to_string(m) + " x " +
                 std::to_string(m) + " matrix"};
  }
  const double pscale = 1.0 + P0.cwiseAbs().maxCoeff();
  if ((P0 - P0.transpose()).cwiseAbs().maxCoeff() > 1e-9 * pscale ||
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(P0).eigenvalues().minCoeff() <
          -1e-9 * pscale) {
    return Error{"Kalman filter: P0 must be symmetric positive semi-definite"};
  }
  LegacyKalmanFilterT f;
  f.mode_ = mode;
  f.N_ = N;
  f.H_ = model.H;
  f.R_ = model.R;
  f.GQG_ = model.ProcessNoise();
  f.has_process_noise_ = model.G.cols() > 0;
  f.x_ = x0;
  f.P_ = P0;
  f.xq_.resize(m);
  f.ax_.resize(m);
  f.tmp_.resize(m);
  f.rowsum_.resize(m);
  f.M_.resize(m, m);
  f.AM_.resize(m, m);
  f.U_.resize(m, r);
  f.K_.setZero(m, r);
  f.KS_.resize(m, r);
  f.S_.resize(r, r);
  f.innov_.setZero(r);
  f.Kt_.resize(r, m);
  f.Reproject();
  return f;
}

template <int M, int R>
void LegacyKalmanFilterT<M, R>::Predict(const Mat& A) {
  // A P A^T + Qz(xq) = A (P - diag xq) A^T + diag(A xq); xq is the point Qz is evaluated at.
  M_ = P_;
  switch (mode_) {
    case estimation::CovarianceMode::kExtended:
      legacy_detail::ProjectOntoSimplexInto(x_, N_, xq_, tmp_);
      break;
    case estimation::CovarianceMode::kConservative:
      xq_.setConstant(N_);
      break;
    case estimation::CovarianceMode::kPlain:
      break;
  }
  if (mode_ != estimation::CovarianceMode::kPlain) M_.diagonal() -= xq_;
  AM_.noalias() = A * M_;
  P_.noalias() = AM_ * A.transpose();
  if (mode_ != estimation::CovarianceMode::kPlain) {
    ax_.noalias() = A * xq_;
    P_.diagonal() += ax_;
  }
  if (has_process_noise_) P_ += GQG_;
  tmp_.noalias() = A * x_;
  x_ = tmp_;
  Reproject();
}

template <int M, int R>
void LegacyKalmanFilterT<M, R>::Update(const OutVec& y) {
  U_.noalias() = P_ * H_.transpose();  // P H^T
  S_ = R_;
  S_.noalias() += H_ * U_;  // H P H^T + R
  llt_.compute(S_);
  Kt_ = U_.transpose();
  llt_.solveInPlace(Kt_);  // K^T = S^-1 H P
  K_ = Kt_.transpose();
  innov_ = y;
  innov_.noalias() -= H_ * x_;
  x_.noalias() += K_ * innov_;
  // Joseph form (I - K H) P (I - K H)^T + K R K^T, expanded with U = P H^T so that it costs
  // O(m^2 r): P - K U^T - U K^T + K S K^T. Valid for any K, symmetric by construction.
  KS_.noalias() = K_ * S_;
  P_.noalias() -= K_ * U_.transpose();
  P_.noalias() -= U_ * K_.transpose();
  P_.noalias() += KS_ * K_.transpose();
  Reproject();
}

template <int M, int R>
void LegacyKalmanFilterT<M, R>::Reproject() {
  const Eigen::Index m = x_.size();
  const double inv_m = 1.0 / static_cast<double>(m);
  x_.array() += (N_ - x_.sum()) * inv_m;
  // P <- Pi sym(P) Pi with Pi = I - 1 1^T / m: P_ij - (c_i + c_j) / m + s / m^2.
  rowsum_ = 0.5 * (P_.rowwise().sum() + P_.colwise().sum().transpose());
  const double s = rowsum_.sum() * inv_m * inv_m;
  for (Eigen::Index j = 0; j < m; ++j) {
    for (Eigen::Index i = 0; i <= j; ++i) {
      const double v = 0.5 * (P_(i, j) + P_(j, i)) - (rowsum_(i) + rowsum_(j)) * inv_m + s;
      P_(i, j) = v;
      P_(j, i) = v;
    }
  }
}

template <int M, int R>
Status LegacyKalmanFilterT<M, R>::PredictChecked(const Eigen::MatrixXd& A) {
  if (Status s =
          estimation::ValidateColumnStochastic(A, estimation::kStochasticTolerance, num_states());
      !s.ok()) {
    return s;
  }
  Predict(Mat(A));
  return Status::Ok();
}

template <int M, int R>
Status LegacyKalmanFilterT<M, R>::UpdateChecked(const Eigen::VectorXd& y) {
  if (y.size() != num_outputs()) {
    return Error{"measurement: must have " + std::to_string(num_outputs()) + " entries, got " +
                 std::to_string(y.size())};
  }
  if (!y.allFinite()) return Error{"measurement: entries must be finite"};
  Update(OutVec(y));
  return Status::Ok();
}

}  // namespace legacy
}  // namespace recruit
