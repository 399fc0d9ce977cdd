// The sparse-A Predict overload against the dense Predict (the reference) and against the
// prediction equations written out with dense matrices; BroadcastTransitionModel's sparse
// pattern and FillSparse against its dense Matrix.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "common/rng.h"
#include "estimation/population_kalman_filter.h"

namespace recruit {
namespace file_kalman_sparse_test {

// m states, N = 60, a force sensor (state i gives 0.45 i / (m - 1) per unit), P0 a random
// PSD matrix (projected onto 1^T P0 = 0 by the filter), x0 a random point of the simplex.
estimation::FilterModel RandomModel(int m, Rng& rng, bool process_noise) {
  estimation::FilterModel f;
  for (int i = 0; i < m; ++i) f.state_names.push_back("s" + std::to_string(i));
  f.N = 60;
  f.H.resize(1, m);
  for (int i = 0; i < m; ++i) f.H(0, i) = 0.45 * i / (m - 1);
  f.R = Eigen::MatrixXd::Constant(1, 1, 0.36);
  if (process_noise) {
    // Columns summing to zero so that 1^T G Qw G^T = 0 (required by the model).
    f.G = Eigen::MatrixXd::Zero(m, 2);
    f.G(0, 0) = 1, f.G(1, 0) = -1, f.G(m - 1, 1) = 1, f.G(m / 2, 1) = -1;
    f.Qw = Eigen::Matrix2d{{0.3, 0.1}, {0.1, 0.2}};
  } else {
    f.G = Eigen::MatrixXd::Zero(m, 0);
    f.Qw = Eigen::MatrixXd::Zero(0, 0);
  }
  f.transition = estimation::TransitionSource::kExplicit;
  Eigen::VectorXd w(m);
  for (int i = 0; i < m; ++i) w(i) = rng.Uniform();
  f.x0 = 60.0 * w / w.sum();
  Eigen::MatrixXd L(m, m);
  for (int i = 0; i < m * m; ++i) L.data()[i] = rng.Uniform() - 0.5;
  f.P0 = 4.0 * L * L.transpose();
  return f;
}

// RandomModel driven by broadcasts of the m-state heating chain (p_on = 0.5).
estimation::FilterModel HeatingChainModel(int m, Rng& rng, bool process_noise) {
  estimation::FilterModel f = RandomModel(m, rng, process_noise);
  f.transition = estimation::TransitionSource::kBroadcast;
  f.broadcast = estimation::BroadcastTransitionModel::HeatingChain(m, 0.5);
  f.state_names = f.broadcast.state_names;
  return f;
}

// A random column-stochastic m x m matrix with 1 to 3 nonzeros per column at random rows.
Eigen::SparseMatrix<double> RandomSparseStochastic(int m, Rng& rng) {
  std::vector<Eigen::Triplet<double>> entries;
  for (int j = 0; j < m; ++j) {
    const int k = std::min(m, 1 + static_cast<int>(rng.Uniform() * 3.0));  // m = 2: at most 2
    std::vector<int> rows;
    while (static_cast<int>(rows.size()) < k) {
      const int i = static_cast<int>(rng.Uniform() * m);
      if (std::find(rows.begin(), rows.end(), i) == rows.end()) rows.push_back(i);
    }
    std::vector<double> v(k);
    double sum = 0;
    for (double& e : v) sum += e = 0.05 + rng.Uniform();
    for (int e = 0; e < k; ++e) entries.emplace_back(rows[e], j, v[e] / sum);
  }
  Eigen::SparseMatrix<double> A(m, m);
  A.setFromTriplets(entries.begin(), entries.end());
  A.makeCompressed();
  return A;
}

double Scale(const Eigen::MatrixXd& P) { return 1.0 + P.cwiseAbs().maxCoeff(); }

// 40 predict + update steps with random sparse A: the sparse and the dense Predict give the
// same estimate and covariance to 1e-12 (relative to the covariance's size) at every step.
template <int M>
void SparseMatchesDense(estimation::CovarianceMode mode, bool process_noise, uint64_t seed,
                        bool avx) {
  Rng rng(seed);
  const int m = M == Eigen::Dynamic ? 20 : M;
  const estimation::FilterModel f = RandomModel(m, rng, process_noise);
  auto sparse = estimation::PopulationKalmanFilterT<M, 1>::Create(f, mode);
  auto dense = estimation::PopulationKalmanFilterT<M, 1>::Create(f, mode);
  ASSERT_TRUE(sparse.ok()) << sparse.error();
  ASSERT_TRUE(dense.ok());
  sparse->set_avx_kernels(avx);
  if (avx && !sparse->avx_kernels()) return;  // no AVX copy in this build or on this CPU
  using Mat = typename estimation::PopulationKalmanFilterT<M, 1>::Mat;
  for (int t = 0; t < 40; ++t) {
    const Eigen::SparseMatrix<double> A = RandomSparseStochastic(m, rng);
    const Mat Ad = Eigen::MatrixXd(A);
    sparse->Predict(A);
    dense->Predict(Ad);
    const double scale = Scale(dense->covariance());
    ASSERT_LT((sparse->covariance() - dense->covariance()).cwiseAbs().maxCoeff(), 1e-12 * scale)
        << "step " << t;
    ASSERT_LT((sparse->estimate() - dense->estimate()).cwiseAbs().maxCoeff(), 1e-12 * 60.0);
    const Eigen::Matrix<double, 1, 1> y(f.H.row(0).dot(dense->estimate()) +
                                        0.6 * (rng.Uniform() - 0.5));
    sparse->Update(y);
    dense->Update(y);
  }
}

template <int M>
void SparseMatchesDense(estimation::CovarianceMode mode, bool process_noise, uint64_t seed) {
  for (bool avx : {false, true}) {
    SCOPED_TRACE(avx ? "AVX kernels" : "baseline kernels");
    SparseMatchesDense<M>(mode, process_noise, seed, avx);
  }
}

TEST(EstimationKalmanSparse, MatchesDensePredictFixedSize) {
  SparseMatchesDense<20>(estimation::CovarianceMode::kExtended, false, 1);
  SparseMatchesDense<20>(estimation::CovarianceMode::kConservative, false, 2);
  SparseMatchesDense<20>(estimation::CovarianceMode::kPlain, false, 3);
  SparseMatchesDense<20>(estimation::CovarianceMode::kExtended, true, 4);
  SparseMatchesDense<3>(estimation::CovarianceMode::kExtended, false, 5);
}

TEST(EstimationKalmanSparse, MatchesDensePredictDynamicSize) {
  SparseMatchesDense<Eigen::Dynamic>(estimation::CovarianceMode::kExtended, false, 6);
  SparseMatchesDense<Eigen::Dynamic>(estimation::CovarianceMode::kConservative, true, 7);
}

// One prediction against the equations with dense matrices (eqs. 16, 22, 26): P' = A P A^T +
// diag(A x) - A diag(x) A^T + G Qw G^T at a feasible x, x' = A x, then the projection onto
// 1^T P = 0 (P already satisfies it, and so does the prediction: no change beyond round-off).
TEST(EstimationKalmanSparse, MatchesPredictionEquations) {
  Rng rng(11);
  const int m = 20;
  const estimation::FilterModel f = RandomModel(m, rng, true);
  auto kf = estimation::PopulationKalmanFilter::Create(f, estimation::CovarianceMode::kExtended);
  ASSERT_TRUE(kf.ok());
  const Eigen::VectorXd x = kf->estimate();
  const Eigen::MatrixXd P = kf->covariance();
  ASSERT_TRUE((x.array() >= 0).all());
  const Eigen::SparseMatrix<double> As = RandomSparseStochastic(m, rng);
  const Eigen::MatrixXd A(As);
  kf->Predict(As);
  const Eigen::MatrixXd expected = A * P * A.transpose() + Eigen::MatrixXd((A * x).asDiagonal()) -
                                   A * x.asDiagonal() * A.transpose() +
                                   f.G * f.Qw * f.G.transpose();
  EXPECT_LT((kf->covariance() - expected).cwiseAbs().maxCoeff(), 1e-11 * Scale(expected));
  EXPECT_LT((kf->estimate() - A * x).cwiseAbs().maxCoeff(), 1e-11 * 60.0);
}

// The identified 20-state models: SparsePattern + FillSparse equal Matrix (exactly: the same
// arithmetic), nonzeros at most 3 per column, and the filters agree to 1e-12 over 64 steps of
// random (p_on, p_off) including the ends 0 and 1.
TEST(EstimationKalmanSparse, IdentifiedBroadcastModels) {
  for (const char* name : {"bench_n60_dt0.5_m20.json", "bench_n60_dt2.0_m20.json"}) {
    SCOPED_TRACE(name);
    auto model = estimation::FilterModel::FromJson(std::string(RECRUIT_SOURCE_DIR) +
                                                   "/models/identified/" + name);
    ASSERT_TRUE(model.ok()) << model.error();
    const estimation::BroadcastTransitionModel& b = model->broadcast;
    ASSERT_EQ(b.num_states(), 20);
    Eigen::SparseMatrix<double> As = b.SparsePattern();
    for (int j = 0; j < 20; ++j) EXPECT_LE(As.col(j).nonZeros(), 3);
    auto sparse = estimation::PopulationKalmanFilterT<20, 1>::Create(
        *model, estimation::CovarianceMode::kExtended);
    auto dense = estimation::PopulationKalmanFilterT<20, 1>::Create(
        *model, estimation::CovarianceMode::kExtended);
    ASSERT_TRUE(sparse.ok()) << sparse.error();
    ASSERT_TRUE(dense.ok());
    Rng rng(13);
    Eigen::VectorXd x = model->x0;
    for (int t = 0; t < 64; ++t) {
      const double p_on = t == 0 ? 0.0 : t == 1 ? 1.0 : rng.Uniform();
      const double p_off = t == 0 ? 1.0 : t == 1 ? 0.0 : rng.Uniform();
      b.FillSparse(p_on, p_off, As);
      const Eigen::MatrixXd A = b.Matrix(p_on, p_off);
      ASSERT_EQ((Eigen::MatrixXd(As) - A).cwiseAbs().maxCoeff(), 0.0) << "step " << t;
      sparse->Predict(As);
      dense->Predict(Eigen::Matrix<double, 20, 20>(A));
      const double scale = Scale(dense->covariance());
      ASSERT_LT((sparse->covariance() - dense->covariance()).cwiseAbs().maxCoeff(), 1e-12 * scale)
          << "step " << t;
      ASSERT_LT((sparse->estimate() - dense->estimate()).cwiseAbs().maxCoeff(), 1e-12 * 60.0);
      x = estimation::SimulateStepAggregate(A, x, rng);
      const Eigen::Matrix<double, 1, 1> y(model->H.row(0).dot(x) + 0.3 * (rng.Uniform() - 0.5));
      sparse->Update(y);
      dense->Update(y);
    }
  }
}

}  // namespace file_kalman_sparse_test
}  // namespace recruit

namespace recruit {
namespace file_kalman_sparse_test {

// The heating / cooling chain: valid, column-stochastic for any (p_on, p_off), at most 3
// nonzeros per column, and its sparse pattern holds every nonzero of the dense matrix.
TEST(EstimationKalmanSparse, HeatingChainIsAValidSparseBroadcastModel) {
  for (int m : {2, 3, 20, 50}) {
    SCOPED_TRACE(m);
    const auto b = estimation::BroadcastTransitionModel::HeatingChain(m, 0.5);
    ASSERT_TRUE(b.Validate().ok()) << b.Validate().error();
    Eigen::SparseMatrix<double> As = b.SparsePattern();
    for (double p : {0.0, 0.37, 1.0}) {
      const Eigen::MatrixXd A = b.Matrix(p, 1.0 - p);
      EXPECT_TRUE(estimation::ValidateColumnStochastic(A).ok());
      b.FillSparse(p, 1.0 - p, As);
      EXPECT_EQ((Eigen::MatrixXd(As) - A).cwiseAbs().maxCoeff(), 0.0);
    }
    for (int j = 0; j < m; ++j) {
      int nnz = 0;
      for (Eigen::SparseMatrix<double>::InnerIterator it(As, j); it; ++it) ++nnz;
      EXPECT_LE(nnz, 3);
    }
  }
}

// PredictBroadcast (the filter's own sparse A, filled in place) against the dense Predict with
// the broadcast model's dense matrix: 64 predict + update steps with random broadcasts, every
// covariance mode, m = 20 and 50 (fixed size) and the dynamic-size filter; equal to 1e-12
// relative at every step.
template <int M>
void BroadcastMatchesDense(int m, estimation::CovarianceMode mode, uint64_t seed, bool avx) {
  Rng rng(seed);
  const estimation::FilterModel f = HeatingChainModel(m, rng, false);
  auto sparse = estimation::PopulationKalmanFilterT<M, 1>::Create(f, mode);
  auto dense = estimation::PopulationKalmanFilterT<M, 1>::Create(f, mode);
  ASSERT_TRUE(sparse.ok()) << sparse.error();
  ASSERT_TRUE(dense.ok());
  ASSERT_TRUE(sparse->has_broadcast());
  sparse->set_avx_kernels(avx);
  if (avx && !sparse->avx_kernels()) return;  // no AVX copy in this build or on this CPU
  for (int t = 0; t < 64; ++t) {
    const double p_on = 0.3 * rng.Uniform(), p_off = 0.3 * rng.Uniform();
    sparse->PredictBroadcast(p_on, p_off);
    dense->Predict(
        typename estimation::PopulationKalmanFilterT<M, 1>::Mat(f.broadcast.Matrix(p_on, p_off)));
    const double scale = Scale(dense->covariance());
    ASSERT_LT((sparse->covariance() - dense->covariance()).cwiseAbs().maxCoeff(), 1e-12 * scale)
        << "step " << t;
    ASSERT_LT((sparse->estimate() - dense->estimate()).cwiseAbs().maxCoeff(), 1e-12 * 60.0);
    // The A of the last PredictBroadcast (filled on demand) is the model's A(p_on, p_off).
    ASSERT_LE((Eigen::MatrixXd(sparse->broadcast_matrix()) - f.broadcast.Matrix(p_on, p_off))
                  .cwiseAbs()
                  .maxCoeff(),
              1e-15);
    const Eigen::Matrix<double, 1, 1> y(f.H.row(0).dot(dense->estimate()) +
                                        0.6 * (rng.Uniform() - 0.5));
    sparse->Update(y);
    dense->Update(y);
  }
}

TEST(EstimationKalmanSparse, PredictBroadcastMatchesDensePredict) {
  for (estimation::CovarianceMode mode :
       {estimation::CovarianceMode::kExtended, estimation::CovarianceMode::kConservative,
        estimation::CovarianceMode::kPlain}) {
    for (bool avx : {false, true}) {
      SCOPED_TRACE(std::string(ToString(mode)) + (avx ? ", AVX kernels" : ", baseline kernels"));
      BroadcastMatchesDense<20>(20, mode, 21, avx);
      BroadcastMatchesDense<50>(50, mode, 22, avx);
      BroadcastMatchesDense<Eigen::Dynamic>(20, mode, 23, avx);
    }
  }
}

// memcmp equality of two filters' estimates and covariances (bit for bit, signed zeros too).
template <class F>
bool BitIdentical(const F& a, const F& b) {
  const auto& Pa = a.covariance();
  const auto& Pb = b.covariance();
  return std::memcmp(Pa.data(), Pb.data(), sizeof(double) * Pa.size()) == 0 &&
         std::memcmp(a.estimate().data(), b.estimate().data(),
                     sizeof(double) * a.estimate().size()) == 0;
}

// The AVX copy of the sparse step's kernels against the baseline copy, 96 steps: broadcasts of
// the heating chain (PredictBroadcast) alternating with random sparse chains (Predict), each
// followed by an update, one measurement in eleven far off so that the extended mode projects
// negative estimates; bit-identical after every predict and every update.
template <int M>
void AvxMatchesBaselineBitwise(int m, estimation::CovarianceMode mode, bool process_noise,
                               uint64_t seed) {
  Rng rng(seed);
  const estimation::FilterModel f = HeatingChainModel(m, rng, process_noise);
  auto base = estimation::PopulationKalmanFilterT<M, 1>::Create(f, mode);
  auto avx = estimation::PopulationKalmanFilterT<M, 1>::Create(f, mode);
  ASSERT_TRUE(base.ok()) << base.error();
  ASSERT_TRUE(avx.ok());
  base->set_avx_kernels(false);
  avx->set_avx_kernels(true);
  ASSERT_TRUE(avx->avx_kernels());
  for (int t = 0; t < 96; ++t) {
    if (t % 2 == 0) {
      const double p_on = rng.Uniform(), p_off = rng.Uniform();
      base->PredictBroadcast(p_on, p_off);
      avx->PredictBroadcast(p_on, p_off);
    } else {
      const Eigen::SparseMatrix<double> A = RandomSparseStochastic(m, rng);
      base->Predict(A);
      avx->Predict(A);
    }
    ASSERT_TRUE(BitIdentical(*base, *avx)) << "predict, step " << t;
    const double outlier = t % 11 == 5 ? 25.0 : 0.0;
    const Eigen::Matrix<double, 1, 1> y(f.H.row(0).dot(base->estimate()) + outlier +
                                        0.6 * (rng.Uniform() - 0.5));
    base->Update(y);
    avx->Update(y);
    ASSERT_TRUE(BitIdentical(*base, *avx)) << "update, step " << t;
  }
}

TEST(EstimationKalmanSparse, AvxKernelsBitIdenticalToBaseline) {
  Rng rng(31);
  auto probe = estimation::PopulationKalmanFilter::Create(RandomModel(4, rng, false),
                                                          estimation::CovarianceMode::kPlain);
  ASSERT_TRUE(probe.ok());
  probe->set_avx_kernels(true);
  if (!probe->avx_kernels()) GTEST_SKIP() << "no AVX copy of the kernels in this build or CPU";
  uint64_t seed = 40;
  for (estimation::CovarianceMode mode :
       {estimation::CovarianceMode::kExtended, estimation::CovarianceMode::kConservative,
        estimation::CovarianceMode::kPlain}) {
    for (bool noise : {false, true}) {
      SCOPED_TRACE(std::string(ToString(mode)) + (noise ? ", process noise" : ""));
      AvxMatchesBaselineBitwise<3>(3, mode, noise, ++seed);
      AvxMatchesBaselineBitwise<20>(20, mode, noise, ++seed);
      AvxMatchesBaselineBitwise<50>(50, mode, noise, ++seed);
      // Dynamic sizes: odd ones (scalar tails, element-wise transposition) and m mod 4 = 2.
      for (int m : {2, 5, 7, 20, 22, 50, 53}) {
        if (m == 2 && noise) continue;  // RandomModel's process noise needs m >= 3
        SCOPED_TRACE(m);
        AvxMatchesBaselineBitwise<Eigen::Dynamic>(m, mode, noise, ++seed);
      }
    }
  }
}

// A filter of a non-broadcast model has no broadcast matrix.
TEST(EstimationKalmanSparse, PredictBroadcastNeedsABroadcastModel) {
  Rng rng(3);
  auto kf = estimation::PopulationKalmanFilter::Create(RandomModel(4, rng, false),
                                                       estimation::CovarianceMode::kExtended);
  ASSERT_TRUE(kf.ok());
  EXPECT_FALSE(kf->has_broadcast());
}

// The r = 1 update (scalar innovation, P - w w^T) against the textbook equations (19), (15)
// and the Joseph form of (20) written out with dense matrices and a matrix inverse.
TEST(EstimationKalmanSparse, ScalarUpdateMatchesJosephForm) {
  Rng rng(5);
  const estimation::FilterModel f = RandomModel(7, rng, false);
  auto kf = estimation::PopulationKalmanFilter::Create(f, estimation::CovarianceMode::kExtended);
  ASSERT_TRUE(kf.ok());
  const Eigen::MatrixXd P = kf->covariance();
  const Eigen::VectorXd x = kf->estimate();
  const Eigen::VectorXd y = Eigen::VectorXd::Constant(1, 7.5);
  const Eigen::MatrixXd S = f.H * P * f.H.transpose() + f.R;
  const Eigen::MatrixXd K = P * f.H.transpose() * S.inverse();
  const Eigen::MatrixXd IKH = Eigen::MatrixXd::Identity(7, 7) - K * f.H;
  const Eigen::MatrixXd P_ref = IKH * P * IKH.transpose() + K * f.R * K.transpose();
  const Eigen::VectorXd x_ref = x + K * (y - f.H * x);
  kf->Update(y);
  EXPECT_LT((kf->covariance() - P_ref).cwiseAbs().maxCoeff(), 1e-12 * Scale(P_ref));
  EXPECT_LT((kf->estimate() - x_ref).cwiseAbs().maxCoeff(), 1e-12 * 60.0);
  EXPECT_EQ(kf->covariance(), kf->covariance().transpose());  // exactly symmetric
}

// Regression (issue 12): Create used to move an Eigen::LLT whose members were never
// initialised (undefined behaviour that UndefinedBehaviorSanitizer reports and aborts on).
// Copies and moves of a created filter, fixed and dynamic, r = 1 and r = 2, keep working.
TEST(EstimationKalmanSparse, CreatedFiltersCopyAndMove) {
  Rng rng(8);
  estimation::FilterModel f = RandomModel(5, rng, false);
  auto a = estimation::PopulationKalmanFilter::Create(f, estimation::CovarianceMode::kExtended);
  ASSERT_TRUE(a.ok());
  estimation::PopulationKalmanFilter b = *a;
  estimation::PopulationKalmanFilter c = std::move(*a);
  b.Update(Eigen::VectorXd::Constant(1, 3.0));
  c.Update(Eigen::VectorXd::Constant(1, 3.0));
  EXPECT_EQ(b.estimate(), c.estimate());
  f.H = Eigen::MatrixXd::Ones(2, 5);
  f.H(1, 0) = 0.0;
  f.R = Eigen::Matrix2d{{0.5, 0.1}, {0.1, 0.4}};
  auto d = estimation::PopulationKalmanFilterT<5, 2>::Create(
      f, estimation::CovarianceMode::kConservative);
  ASSERT_TRUE(d.ok()) << d.error();
  auto e = std::move(*d);
  e.Update(Eigen::Vector2d(60.0, 50.0));
  EXPECT_TRUE(e.estimate().allFinite());
  EXPECT_NEAR(e.estimate().sum(), 60.0, 1e-9);
}

}  // namespace file_kalman_sparse_test
}  // namespace recruit
