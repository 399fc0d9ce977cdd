// The Kalman filter for population Markov chains (Odhner and Asada, ACC 2010, eqs. 15-27).
//
//   predict  X^(t+1|t) = A X^(t)                                              (16)
//            P(t+1|t)  = A P A^T + G Qw G^T + Qz                              (22), (27)
//   gain     K = P H^T (H P H^T + R)^-1                                       (19)
//   update   X^ = X^(t|t-1) + K (y - H X^(t|t-1))                             (15), (17)
//            P  = (I - K H) P (I - K H)^T + K R K^T   (Joseph form of (20))
// For r = 1 the innovation variance is a scalar s (no factorisation) and the Joseph form with
// the optimal gain is exactly P - u u^T / s, u = P H^T.
//
// A broadcast model's A is sparse (at most 3 nonzeros per column): PredictBroadcast(p_on,
// p_off) fills the filter's own sparse A in place and predicts in O(m nnz(A)) (docs/
// equations.md); this is the call a controller with a broadcast model uses.
//
// Qz depends on the covariance mode (docs/equations.md):
//   kExtended:     Qz(X^) = diag(A X^) - A diag(X^) A^T at the a-posteriori estimate (26),
//                  with X^ first projected onto {n_i >= 0, sum n_i = N} so that Qz is PSD;
//   kConservative: Qz(N 1) = N (diag(A 1) - A A^T), which dominates Qz(X) in the PSD order for
//                  every admissible X (0 <= n_i <= N);
//   kPlain:        no Qz (the standard Kalman filter, for comparison).
// Both terms are folded into one product: A P A^T + Qz(x) = A (P - diag x) A^T + diag(A x).
//
// The total N is known exactly, so 1^T P = 0 and 1^T X^ = N are invariants of the equations
// (1^T A = 1^T, 1^T Qz = 0, 1^T G Qw G^T = 0 by validation, hence 1^T K = 0). Round-off is
// removed by projecting X^ onto sum = N (every step) and P onto the subspace 1^T P = 0 (every
// dense step; every kSparseReprojectPeriod sparse predictions, since the sparse step keeps
// 1^T P = 0 algebraically and its round-off drift is O(eps) per step).
//
// PopulationKalmanFilterT<M, R> is the fixed-size filter for m = M states and r = R outputs
// (no heap allocation in Predict / Update); PopulationKalmanFilter is the dynamic-size one.
// Parameters (H, R, G Qw G^T, N) are fixed at Create; the state is (X^, P).
#pragma once

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <utility>
#include <vector>
#ifdef __SSE2__
#include <emmintrin.h>
#endif
// The portable x86-64 build carries a second copy of the sparse step's kernels compiled for AVX
// (sparse_step_kernels.h), chosen at run time; builds that already target AVX do not.
#if defined(__x86_64__) && defined(__SSE2__) && !defined(__AVX__) && defined(__GNUC__)
#define RECRUIT_KF_AVX_CLONE 1
#include <immintrin.h>
#endif

#include "common/cpu_features.h"
#include "common/result.h"
#include "estimation/filter_model.h"
#include "estimation/population_chain.h"

namespace recruit::estimation {

enum class CovarianceMode { kExtended, kConservative, kPlain };

// "extended", "conservative", "plain".
const char* ToString(CovarianceMode mode);
Result<CovarianceMode> ParseCovarianceMode(const std::string& name);

namespace kf_detail {
inline bool CpuHasAvx();  // below
}  // namespace kf_detail

template <int M, int R>
class PopulationKalmanFilterT {
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
  static Result<PopulationKalmanFilterT> Create(const FilterModel& model, CovarianceMode mode,
                                                const Eigen::VectorXd& x0,
                                                const Eigen::MatrixXd& P0);
  // With the model's own initial belief (model.x0, model.P0).
  static Result<PopulationKalmanFilterT> Create(const FilterModel& model, CovarianceMode mode) {
    return Create(model, mode, model.x0, model.P0);
  }

  // Time update with the transition A(t) (eqs. 16, 22/27). A must be column-stochastic (the
  // caller validates it, or uses PredictChecked). A step without a measurement is Predict alone.
  void Predict(const Mat& A);
  // The same for a sparse A (column-major; e.g. BroadcastTransitionModel::SparsePattern filled
  // by FillSparse), converted to compressed rows in preallocated workspaces: A (P - diag xq) A^T
  // in about 3 m nnz(A) flops (PredictRows) instead of two dense m x m products. A must be
  // m x m and column-stochastic (not checked); no allocation. Equal to Predict(Mat(A)) up to
  // round-off.
  void Predict(const Eigen::SparseMatrix<double>& A);
  // The natural call for a broadcast model (model.transition == kBroadcast): fills the filter's
  // own sparse A(p_on, p_off) in place (the arithmetic of BroadcastTransitionModel::FillSparse,
  // into the compressed rows of the pattern built at Create) and predicts with it, O(m nnz(A)),
  // no allocation. p_on, p_off in [0, 1]
  // (not checked; BroadcastTransitionModel::ValidateInputs). Not for other transition sources
  // (has_broadcast() is false; then this is a no-op guarded by an assertion in debug builds).
  void PredictBroadcast(double p_on, double p_off);
  // Sparse predictions between two projections of P onto 1^T P = 0 (see the header comment).
  static constexpr int kSparseReprojectPeriod = 16;
  bool has_broadcast() const { return has_broadcast_; }
  // The A of the last PredictBroadcast (the broadcast pattern, values of that call; filled here,
  // not in every step).
  const Eigen::SparseMatrix<double>& broadcast_matrix() const {
    if (has_broadcast_) broadcast_.FillSparse(last_p_on_, last_p_off_, As_);
    return As_;
  }
  // Which copy of the sparse step's kernels runs (PredictBroadcast, Predict(SparseMatrix), the
  // r = 1 Update): the portable x86-64 build has a second copy compiled for AVX, chosen at
  // Create when the CPU has AVX and m >= kAvxMinStates. Both give bit-identical results.
  // set_avx_kernels(false) forces the baseline copy, true the AVX copy where it can run (tests,
  // benchmarks).
  bool avx_kernels() const { return avx_; }
  // Below this many states the AVX copy is not the default: it has little to do 4 lanes wide,
  // and its calls cost more (m = 2: the controller's step measured 3-6 % slower with it).
  static constexpr int kAvxMinStates = 8;
  void set_avx_kernels(bool on) { avx_ = on && kf_detail::CpuHasAvx(); }
  // Measurement update with y(t) (eqs. 15, 17, 19, 20 in Joseph form). The measurement noise
  // is R + n R_transit + n^2 R_transit2, n = TransitCount() (the model's; R alone when it has
  // neither), evaluated at the predicted estimate.
  void Update(const OutVec& y);
  // The expected number of units in transit at the current estimate: the sum of max(0, x_j)
  // weighted by FilterModel::TransitWeights, in state order (0 without transit noise).
  double TransitCount() const {
    double n = 0.0;
    if (!has_transit_noise_) return n;
    for (Eigen::Index j = 0; j < x_.size(); ++j) {
      if (x_[j] > 0.0) n += transit_weights_[j] * x_[j];
    }
    return n;
  }

  // Replaces the output model for the next Updates: H (r x m, the force per unit in each state,
  // which may depend on the plant's measured configuration, e.g. the tendon's length) and R
  // (r x r, symmetric positive definite; the state-independent part: the model's R_transit
  // still adds TransitCount() R_transit). Sizes must match (not checked); no allocation.
  void SetOutput(const OutputMat& H, const OutMat& noise) {
    H_ = H;
    R_ = noise;
  }

  // Predict / Update after checking the input (sizes, finite, column-stochastic).
  Status PredictChecked(const Eigen::MatrixXd& A);
  Status UpdateChecked(const Eigen::VectorXd& y);

  // Replaces the belief (no checks beyond the projections).
  void Reset(const Vec& x0, const Mat& P0) {
    x_ = x0;
    P_ = P0;
    Reproject();
  }

  const Vec& estimate() const { return x_; }                  // X^, counts per state, sums to N
  const Mat& covariance() const { return P_; }                // P
  const OutVec& innovation() const { return innov_; }         // y - H X^(t|t-1) of the last Update
  const OutMat& innovation_covariance() const { return S_; }  // H P H^T + R of the last Update
  const GainMat& gain() const { return K_; }                  // K of the last Update
  CovarianceMode mode() const { return mode_; }
  double population() const { return N_; }
  int num_states() const { return static_cast<int>(x_.size()); }
  int num_outputs() const { return static_cast<int>(H_.rows()); }
  const OutputMat& H() const { return H_; }

 private:
  PopulationKalmanFilterT() = default;
  // Sets xq_, the point Qz is evaluated at (per the mode).
  void SetQzPoint();
  // Sets M_ = P - diag xq (xq per the mode) before the covariance prediction.
  void PrepareCovariancePredict();
  // The r = 1 update: scalar innovation variance, no factorisation.
  void UpdateScalar(double y);
  template <class Kernels>  // kf_detail::base::Kernels or kf_detail::avx::Kernels
  void UpdateScalarWith(double y);
  // Adds diag(A xq) and G Qw G^T to P_ (ax_ = A xq computed by the caller), x_ = tmp_ (= A x),
  // re-projects.
  void FinishPredict();
  // Projects X^ onto sum = N and P onto Pi sym(P) Pi, Pi = I - 1 1^T / m (any P).
  void Reproject();
  // The same after copying P's upper triangle to its lower one (the predict and update compute
  // P up to round-off asymmetry; the upper triangle is taken as exact), cheaper than Reproject.
  void MirrorUpperAndReproject();
  // Reproject for an exactly symmetric P.
  void ReprojectSymmetric();
  // The sparse prediction with A in compressed-row form (row i: entries ptr[i]..ptr[i+1] - 1,
  // columns col[], values val[]): P = A (P - diag xq) A^T + diag(A xq) + G Qw G^T, x = A x.
  void PredictRows(const int* ptr, const int* col, const double* val);
  template <class Kernels>
  void PredictRowsWith(const int* ptr, const int* col, const double* val);

  CovarianceMode mode_ = CovarianceMode::kExtended;
  double N_ = 0.0;
  OutputMat H_;
  OutMat R_;
  OutMat R_transit_;     // per unit in transit (has_transit_noise_ only)
  OutMat R_transit2_;    // per squared count of units in transit (has_transit_noise_ only)
  Vec transit_weights_;  // FilterModel::TransitWeights
  bool has_transit_noise_ = false;
  Mat GQG_;  // G Qw G^T, precomputed
  bool has_process_noise_ = false;
  // State.
  Vec x_;
  Mat P_;
  // Workspaces (sized at Create so that Predict / Update do not allocate).
  Vec xq_, ax_, tmp_, rowsum_, kw_;
  Mat M_, AM_;
  GainMat U_, K_, KS_;
  OutMat S_;
  OutVec innov_;
  Eigen::Matrix<double, R, M> Kt_;
  Eigen::LLT<OutMat> llt_;  // r > 1 only; computed once at Create so that no member is
                            // left uninitialised (moving an uninitialised LLT is undefined)
  // PredictBroadcast: the model's broadcast transition and the sparse A it fills.
  bool has_broadcast_ = false;
  BroadcastTransitionModel broadcast_;
  mutable Eigen::SparseMatrix<double> As_;  // values filled by broadcast_matrix()
  double last_p_on_ = 0.0, last_p_off_ = 0.0;
  // Its compressed-row form, built at Create: per entry the column, the value of `interior`,
  // 1 if the row is the column's switch target (else 0), and 1 if the column is an on state
  // (else 0) and its complement, so that the values are filled in one vectorised loop.
  std::vector<int> bc_ptr_, bc_col_;
  std::vector<double> bc_base_, bc_val_, bc_target_, bc_on_, bc_off_;
  // Predict(SparseMatrix): A converted to compressed rows (sized m^2 at Create, no allocation).
  std::vector<int> sp_ptr_, sp_col_, sp_fill_;
  std::vector<double> sp_val_;
  std::vector<int> iota_;  // 0, 1, ..., m - 1 (P h as a combination of all columns of P)
  int sparse_steps_ = 0;   // sparse predictions since P was last projected onto 1^T P = 0
  bool xq_is_x_ = false;   // SetQzPoint: xq = x (the extended mode, x feasible); xq_ not set
  bool avx_ = false;       // the sparse step runs the AVX copy of its kernels
};

using PopulationKalmanFilter = PopulationKalmanFilterT<Eigen::Dynamic, Eigen::Dynamic>;

// ---------------------------------------------------------------------------------------------
// Implementation.

namespace kf_detail {

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

// Eigen's packet of doubles for the build's instruction set (2 with SSE2, 4 with AVX); pmadd
// is one fused multiply-add where the build has FMA (x86-64-v3), a multiply and an add otherwise.
using Packet = Eigen::internal::packet_traits<double>::type;
constexpr int kPacket = Eigen::internal::packet_traits<double>::size;

// The sparse step's kernels for the build's instruction set.
namespace base {
#define RECRUIT_KF_AVX 0
#define RECRUIT_KF_INLINE EIGEN_ALWAYS_INLINE
#define RECRUIT_KF_PASS EIGEN_ALWAYS_INLINE
#include "estimation/sparse_step_kernels.h"
#undef RECRUIT_KF_AVX
#undef RECRUIT_KF_INLINE
#undef RECRUIT_KF_PASS
}  // namespace base

#ifdef RECRUIT_KF_AVX_CLONE
// The same kernels compiled for AVX (no FMA; bit-identical results), for CPUs that have it.
namespace avx {
#define RECRUIT_KF_AVX 1
#define RECRUIT_KF_INLINE inline __attribute__((always_inline, target("avx")))
#define RECRUIT_KF_PASS __attribute__((noinline, target("avx")))
#include "estimation/sparse_step_kernels.h"
#undef RECRUIT_KF_AVX
#undef RECRUIT_KF_INLINE
#undef RECRUIT_KF_PASS
}  // namespace avx

// Whether this CPU and its operating system run AVX (checked once per process).
inline bool CpuHasAvx() {
  static const bool has = CpuRunsAvx();
  return has;
}
#else
inline bool CpuHasAvx() { return false; }
#endif

}  // namespace kf_detail

template <int M, int R>
Result<PopulationKalmanFilterT<M, R>> PopulationKalmanFilterT<M, R>::Create(
    const FilterModel& model, CovarianceMode mode, const Eigen::VectorXd& x0,
    const Eigen::MatrixXd& P0) {
  if (Status s = model.Validate(); !s.ok()) return Error{s.error(), s.code()};
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
  PopulationKalmanFilterT f;
  f.mode_ = mode;
  f.N_ = N;
  f.H_ = model.H;
  f.R_ = model.R;
  f.has_transit_noise_ = model.has_transit_noise();
  auto or_zero = [r](const Eigen::MatrixXd& t) {
    return t.size() > 0 ? OutMat(t) : OutMat(OutMat::Zero(r, r));
  };
  f.R_transit_ = f.has_transit_noise_ ? or_zero(model.R_transit) : OutMat::Zero(r, r);
  f.R_transit2_ = f.has_transit_noise_ ? or_zero(model.R_transit2) : OutMat::Zero(r, r);
  f.transit_weights_ = model.TransitWeights();
  f.GQG_ = model.ProcessNoise();
  f.has_process_noise_ = model.G.cols() > 0;
  f.x_ = x0;
  f.P_ = P0;
  f.avx_ = kf_detail::CpuHasAvx() && m >= kAvxMinStates;
  f.xq_.resize(m);
  f.ax_.resize(m);
  f.tmp_.resize(m);
  f.rowsum_.resize(m);
  f.kw_.resize(m);
  f.M_.resize(m, m);
  f.AM_.resize(m, m);
  f.U_.resize(m, r);
  f.K_.setZero(m, r);
  f.KS_.resize(m, r);
  f.S_.setZero(r, r);
  f.innov_.setZero(r);
  f.Kt_.resize(r, m);
  f.llt_.compute(OutMat::Identity(r, r));
  f.sp_ptr_.assign(m + 1, 0);
  f.sp_fill_.assign(m, 0);
  f.sp_col_.assign(static_cast<size_t>(m) * m, 0);
  f.sp_val_.assign(static_cast<size_t>(m) * m, 0.0);
  f.iota_.resize(m);
  for (int i = 0; i < m; ++i) f.iota_[i] = i;
  if (model.transition == TransitionSource::kBroadcast) {
    f.has_broadcast_ = true;
    f.broadcast_ = model.broadcast;
    f.As_ = model.broadcast.SparsePattern();
    // Compressed rows of the pattern (rows in order, columns in order within a row).
    const Eigen::SparseMatrix<double>& A = f.As_;
    f.bc_ptr_.assign(m + 1, 0);
    for (int l = 0; l < m; ++l) {
      for (Eigen::SparseMatrix<double>::InnerIterator it(A, l); it; ++it) ++f.bc_ptr_[it.row() + 1];
    }
    for (int i = 0; i < m; ++i) f.bc_ptr_[i + 1] += f.bc_ptr_[i];
    const size_t nnz = static_cast<size_t>(A.nonZeros());
    f.bc_col_.assign(nnz, 0);
    f.bc_base_.assign(nnz, 0.0);
    f.bc_val_.assign(nnz, 0.0);
    f.bc_target_.assign(nnz, 0.0);
    f.bc_on_.assign(nnz, 0.0);
    f.bc_off_.assign(nnz, 0.0);
    std::vector<int> next(f.bc_ptr_.begin(), f.bc_ptr_.end() - 1);
    const BroadcastTransitionModel& b = model.broadcast;
    for (int l = 0; l < m; ++l) {
      const int target = b.is_on[l] ? b.off_target[l] : b.on_target[l];
      for (Eigen::SparseMatrix<double>::InnerIterator it(A, l); it; ++it) {
        const int i = static_cast<int>(it.row());
        const int e = next[i]++;
        f.bc_col_[e] = l;
        f.bc_base_[e] = b.interior(i, l);
        f.bc_target_[e] = i == target ? 1.0 : 0.0;
        f.bc_on_[e] = b.is_on[l] ? 1.0 : 0.0;
        f.bc_off_[e] = b.is_on[l] ? 0.0 : 1.0;
      }
    }
  }
  f.Reproject();
  return f;
}

template <int M, int R>
void PopulationKalmanFilterT<M, R>::SetQzPoint() {
  xq_is_x_ = false;
  switch (mode_) {
    case CovarianceMode::kExtended:
      // Feasible x (the usual case): xq = x, no copy (PredictRows reads x_).
      xq_is_x_ = x_.minCoeff() >= 0.0;
      if (!xq_is_x_) kf_detail::ProjectOntoSimplexInto(x_, N_, xq_, tmp_);
      break;
    case CovarianceMode::kConservative:
      xq_.setConstant(N_);
      break;
    case CovarianceMode::kPlain:
      xq_.setZero();
      break;
  }
}

template <int M, int R>
void PopulationKalmanFilterT<M, R>::PrepareCovariancePredict() {
  // A P A^T + Qz(xq) = A (P - diag xq) A^T + diag(A xq); xq is the point Qz is evaluated at.
  SetQzPoint();
  if (xq_is_x_) xq_ = x_;
  M_ = P_;
  if (mode_ != CovarianceMode::kPlain) M_.diagonal() -= xq_;
}

template <int M, int R>
void PopulationKalmanFilterT<M, R>::FinishPredict() {
  if (mode_ != CovarianceMode::kPlain) P_.diagonal() += ax_;
  if (has_process_noise_) P_ += GQG_;
  x_ = tmp_;
  MirrorUpperAndReproject();
}

template <int M, int R>
void PopulationKalmanFilterT<M, R>::Predict(const Mat& A) {
  PrepareCovariancePredict();
  AM_.noalias() = A * M_;
  if (M != Eigen::Dynamic ? M < 8 : A.rows() < 16) {
    // Small sizes: Eigen's full product beats its triangular product (measured).
    P_.noalias() = AM_ * A.transpose();
  } else {
    // P is symmetric: only its upper triangle is computed (mirrored before the projection).
    P_.template triangularView<Eigen::Upper>() = AM_ * A.transpose();
  }
  if (mode_ != CovarianceMode::kPlain) ax_.noalias() = A * xq_;
  tmp_.noalias() = A * x_;
  FinishPredict();
}

template <int M, int R>
void PopulationKalmanFilterT<M, R>::Predict(const Eigen::SparseMatrix<double>& A) {
  // Compressed columns to compressed rows (a counting sort, O(nnz + m), into the workspaces).
  const int m = static_cast<int>(x_.size());
  std::fill(sp_ptr_.begin(), sp_ptr_.end(), 0);
  for (int l = 0; l < m; ++l) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, l); it; ++it) ++sp_ptr_[it.row() + 1];
  }
  for (int i = 0; i < m; ++i) {
    sp_ptr_[i + 1] += sp_ptr_[i];
    sp_fill_[i] = sp_ptr_[i];
  }
  for (int l = 0; l < m; ++l) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, l); it; ++it) {
      const int e = sp_fill_[it.row()]++;
      sp_col_[e] = l;
      sp_val_[e] = it.value();
    }
  }
  PredictRows(sp_ptr_.data(), sp_col_.data(), sp_val_.data());
}

template <int M, int R>
void PopulationKalmanFilterT<M, R>::PredictBroadcast(double p_on, double p_off) {
  eigen_assert(has_broadcast_ && "PredictBroadcast needs a broadcast model");
  if (!has_broadcast_) return;
  // The values of A(p_on, p_off), the arithmetic of BroadcastTransitionModel::FillSparse, into
  // the compressed rows (As_ is filled only when broadcast_matrix() is called).
  last_p_on_ = p_on;
  last_p_off_ = p_off;
#ifdef RECRUIT_KF_AVX_CLONE
  if (avx_) {
    kf_detail::avx::Kernels::FillBroadcast(bc_val_.size(), p_on, p_off, bc_on_.data(),
                                           bc_off_.data(), bc_base_.data(), bc_target_.data(),
                                           bc_val_.data());
    return PredictRowsWith<kf_detail::avx::Kernels>(bc_ptr_.data(), bc_col_.data(), bc_val_.data());
  }
#endif
  kf_detail::base::Kernels::FillBroadcast(bc_val_.size(), p_on, p_off, bc_on_.data(),
                                          bc_off_.data(), bc_base_.data(), bc_target_.data(),
                                          bc_val_.data());
  PredictRowsWith<kf_detail::base::Kernels>(bc_ptr_.data(), bc_col_.data(), bc_val_.data());
}

template <int M, int R>
void PopulationKalmanFilterT<M, R>::PredictRows(const int* ptr, const int* col, const double* val) {
#ifdef RECRUIT_KF_AVX_CLONE
  if (avx_) return PredictRowsWith<kf_detail::avx::Kernels>(ptr, col, val);
#endif
  PredictRowsWith<kf_detail::base::Kernels>(ptr, col, val);
}

template <int M, int R>
template <class Kernels>
void PopulationKalmanFilterT<M, R>::PredictRowsWith(const int* ptr, const int* col,
                                                    const double* val) {
  SetQzPoint();
  const Eigen::Index m = x_.size();
  const bool qz = mode_ != CovarianceMode::kPlain;
  // xq = x (extended mode, x feasible): A xq = A x, computed once.
  const bool ax_is_tmp = qz && xq_is_x_;
  const double* xq = xq_is_x_ ? x_.data() : xq_.data();
  const double* P = P_.data();
  double* B = AM_.data();
  // P is overwritten below: P - diag xq is formed in place.
  if (qz) {
    for (Eigen::Index i = 0; i < m; ++i) P_(i, i) -= xq[i];
  }
  // Pass 1, B = (P - diag xq) A^T column by column: B(:, i) = sum over row i of A of
  // A(i, l) (P - diag xq)(:, l); each column of B written once (no zeroing), 2 m nnz(A) flops;
  // with A x and A xq.
  Kernels::template CombineRows<M>(B, P, m, ptr, col, val);
  const double* x = x_.data();
  for (Eigen::Index i = 0; i < m; ++i) {
    double ti = 0.0;
    for (int e = ptr[i]; e < ptr[i + 1]; ++e) ti += val[e] * x[col[e]];
    tmp_(i) = ti;
  }
  if (qz && !ax_is_tmp) {
    for (Eigen::Index i = 0; i < m; ++i) {
      double ai = 0.0;
      for (int e = ptr[i]; e < ptr[i + 1]; ++e) ai += val[e] * xq[col[e]];
      ax_(i) = ai;
    }
  }
  const double* ax = ax_is_tmp ? tmp_.data() : ax_.data();
  // Pass 2, P = A B, upper triangle: column j is sum over row j of A of A(j, l) B(l, 0..j)^T.
  // Rows of B are made columns by one transposition so that this pass is contiguous too; the
  // diagonal term and G Qw G^T are added in the same pass, then the upper triangle is mirrored
  // (P stays exactly symmetric). About m nnz(A) flops.
  double* Bt = M_.data();
  Kernels::Transpose(B, Bt, m);
  Kernels::template UpperProduct<M>(P_.data(), Bt, m, ptr, col, val, qz ? ax : nullptr,
                                    has_process_noise_ ? GQG_.data() : nullptr);
  Kernels::MirrorUpper(P_.data(), m);
  x_ = tmp_;
  if (++sparse_steps_ >= kSparseReprojectPeriod) {
    sparse_steps_ = 0;
    ReprojectSymmetric();
  } else {
    x_.array() += (N_ - x_.sum()) / static_cast<double>(m);
  }
}

template <int M, int R>
void PopulationKalmanFilterT<M, R>::UpdateScalar(double y) {
#ifdef RECRUIT_KF_AVX_CLONE
  if (avx_) return UpdateScalarWith<kf_detail::avx::Kernels>(y);
#endif
  UpdateScalarWith<kf_detail::base::Kernels>(y);
}

template <int M, int R>
template <class Kernels>
void PopulationKalmanFilterT<M, R>::UpdateScalarWith(double y) {
  // r = 1: S = h P h^T + R is a scalar, K = P h^T / S; no factorisation, no matrix inverse.
  const Eigen::Index m = x_.size();
  const auto h = H_.row(0);
  auto u = U_.col(0);
  auto k = K_.col(0);
  // P h^T as a combination of P's columns, three per pass over u (no call into Eigen's general
  // matrix-vector kernel, whose set-up dominates at these sizes). H is 1 x m: h is contiguous.
  Kernels::template MatVec<M>(u.data(), P_.data(), m, iota_.data(), H_.data());
  double noise = R_(0, 0);
  if (has_transit_noise_) {
    const double n = TransitCount();
    noise += n * R_transit_(0, 0) + (n * n) * R_transit2_(0, 0);
  }
  const double s = h.dot(u) + noise;
  S_(0, 0) = s;
  k = u / s;
  innov_(0) = y - h.dot(x_);
  x_ += innov_(0) * k;
  // Joseph form (I - K H) P (I - K H)^T + K R K^T with the optimal gain k = u / s reduces to
  // P - u u^T / s = P - w w^T, w = u / sqrt(s): 2 m^2 flops instead of 7 m^2 for the expanded
  // form, and w_i w_j == w_j w_i exactly (also as a fused multiply-add), so P stays exactly
  // symmetric. 1^T P = 0 before gives 1^T u = 0, so the update keeps 1^T P = 0 up to round-off,
  // removed at the next Predict; the estimate is re-centred on sum = N at once (O(m)).
  kw_ = u / std::sqrt(s);
  Kernels::template SubtractOuter<M>(P_.data(), kw_.data(), m);
  x_.array() += (N_ - x_.sum()) / static_cast<double>(m);
}

template <int M, int R>
void PopulationKalmanFilterT<M, R>::Update(const OutVec& y) {
  if (R == 1 || (R == Eigen::Dynamic && H_.rows() == 1)) {
    UpdateScalar(y(0));
    return;
  }
  U_.noalias() = P_ * H_.transpose();  // P H^T
  S_ = R_;
  if (has_transit_noise_) {
    const double n = TransitCount();
    S_ += n * R_transit_ + (n * n) * R_transit2_;
  }
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
  MirrorUpperAndReproject();
}

template <int M, int R>
void PopulationKalmanFilterT<M, R>::Reproject() {
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
void PopulationKalmanFilterT<M, R>::MirrorUpperAndReproject() {
  const Eigen::Index m = x_.size();
  for (Eigen::Index i = 0; i < m; ++i) {
    for (Eigen::Index j = i + 1; j < m; ++j) P_(j, i) = P_(i, j);  // contiguous writes
  }
  ReprojectSymmetric();
}

template <int M, int R>
void PopulationKalmanFilterT<M, R>::ReprojectSymmetric() {
  const Eigen::Index m = x_.size();
  const double inv_m = 1.0 / static_cast<double>(m);
  x_.array() += (N_ - x_.sum()) * inv_m;
  // As Reproject with sym(P) = P: column sums are the row sums (contiguous), and the update
  // P_ij - (c_i + c_j) / m + s / m^2 is the same arithmetic for (i, j) and (j, i), so P stays
  // exactly symmetric; column by column, so that it vectorises.
  rowsum_ = P_.colwise().sum().transpose();
  const double s = rowsum_.sum() * inv_m * inv_m;
  for (Eigen::Index j = 0; j < m; ++j) {
    P_.col(j).array() -= (rowsum_.array() + rowsum_(j)) * inv_m - s;
  }
}

template <int M, int R>
Status PopulationKalmanFilterT<M, R>::PredictChecked(const Eigen::MatrixXd& A) {
  if (Status s = ValidateColumnStochastic(A, kStochasticTolerance, num_states()); !s.ok()) {
    return s;
  }
  Predict(Mat(A));
  return Status::Ok();
}

template <int M, int R>
Status PopulationKalmanFilterT<M, R>::UpdateChecked(const Eigen::VectorXd& y) {
  if (y.size() != num_outputs()) {
    return Error{"measurement: must have " + std::to_string(num_outputs()) + " entries, got " +
                 std::to_string(y.size())};
  }
  if (!y.allFinite()) return Error{"measurement: entries must be finite"};
  Update(OutVec(y));
  return Status::Ok();
}

// Compiled once, in population_kalman_filter.cc; other files use these without instantiating them
// again (each instantiation is tens of seconds of compile time).
extern template class PopulationKalmanFilterT<Eigen::Dynamic, Eigen::Dynamic>;
extern template class PopulationKalmanFilterT<2, 1>;
extern template class PopulationKalmanFilterT<3, 1>;
extern template class PopulationKalmanFilterT<20, 1>;

}  // namespace recruit::estimation
