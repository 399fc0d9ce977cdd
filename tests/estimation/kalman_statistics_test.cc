// Statistical behaviour of the population Kalman filter against Monte Carlo runs of the chain
// (each band stated where it is used), the no-data limits of eqs. 29-30 and 36, and its
// numerical invariants over 10^6 steps.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <vector>

#include "estimation/population_chain.h"
#include "estimation/population_kalman_filter.h"
#include "test_util.h"

namespace recruit {
namespace file_kalman_statistics_test {

using testing_util::ThreeStateModel;

constexpr int kRuns = 2000;
constexpr int kSteps = 30;

// The open-loop broadcast schedule (it does not depend on the data): recruit, hold, release.
Eigen::MatrixXd OpenLoopA(const estimation::FilterModel& f, int t) {
  const double p_on = t < 10 ? 0.3 : (t < 20 ? 0.08 : 0.02);
  const double p_off = t < 10 ? 0.02 : (t < 20 ? 0.08 : 0.25);
  return f.broadcast.Matrix(p_on, p_off);
}

// kRuns closed-form-free Monte Carlo runs of the three-state chain (N = 60) with a noisy force
// sensor, filtered by the Kalman filter in `mode`. Record per run and step: the true X(t), the
// a-posteriori X^(t), P(t) and z(t) = X(t+1) - A(t) X(t).
struct MonteCarlo {
  std::vector<std::vector<Eigen::VectorXd>> x, xhat, z;
  std::vector<std::vector<Eigen::MatrixXd>> P;
};

MonteCarlo RunMonteCarlo(estimation::CovarianceMode mode) {
  const estimation::FilterModel f = ThreeStateModel(60, 0.6);
  MonteCarlo mc;
  mc.x.resize(kRuns);
  mc.xhat.resize(kRuns);
  mc.z.resize(kRuns);
  mc.P.resize(kRuns);
  for (int run = 0; run < kRuns; ++run) {
    Rng rng(Rng::DeriveSeed(2024, run));
    auto kf = estimation::PopulationKalmanFilterT<3, 1>::Create(f, mode);
    EXPECT_TRUE(kf.ok());
    Eigen::VectorXd x = f.x0;
    for (int t = 0; t < kSteps; ++t) {
      if (t > 0) kf->Predict(OpenLoopA(f, t - 1));
      kf->Update(testing_util::Measure(f, x, rng));
      mc.x[run].push_back(x);
      mc.xhat[run].push_back(kf->estimate());
      mc.P[run].push_back(kf->covariance());
      const Eigen::MatrixXd A = OpenLoopA(f, t);
      const Eigen::VectorXd next = estimation::SimulateStepAggregate(A, x, rng);
      mc.z[run].push_back(next - A * x);
      x = next;
    }
  }
  return mc;
}

const MonteCarlo& Extended() {
  static const MonteCarlo mc = RunMonteCarlo(estimation::CovarianceMode::kExtended);
  return mc;
}

// Mean and standard error of a per-run quantity.
template <class F>
std::pair<double, double> MeanAndError(F f) {
  double s1 = 0, s2 = 0;
  for (int run = 0; run < kRuns; ++run) {
    const double v = f(run);
    s1 += v;
    s2 += v * v;
  }
  const double mean = s1 / kRuns;
  return {mean, std::sqrt((s2 / kRuns - mean * mean) / kRuns)};
}

// With an open-loop A(t), trace P(t) is the filter's own prediction of the mean squared error
// E|X^(t) - X(t)|^2. Band: the difference of the two run means must be within 4 standard errors
// of the per-run difference |e|^2 - trace P (P varies with the data through Qz(X^)).
TEST(EstimationKalmanStatistics, TracePMatchesMonteCarloMeanSquaredError) {
  const MonteCarlo& mc = Extended();
  for (int t : {3, 8, 15, 22, 29}) {
    const auto [diff, se] = MeanAndError(
        [&](int r) { return (mc.xhat[r][t] - mc.x[r][t]).squaredNorm() - mc.P[r][t].trace(); });
    const auto [mse, mse_se] =
        MeanAndError([&](int r) { return (mc.xhat[r][t] - mc.x[r][t]).squaredNorm(); });
    std::cout << "step " << t << ": MC mean |e|^2 " << mse << " +- " << mse_se << ", mean trace P "
              << mse - diff << ", difference " << diff << " +- " << se << "\n";
    EXPECT_LT(std::abs(diff), 4.0 * se)
        << "step " << t << ": MSE " << mse << " +- " << mse_se << ", mean trace P " << mse - diff;
  }
}

// The same check on the plain filter (no Qz) must fail: its trace P is far below the real MSE.
// This shows the band above can tell the paper's covariance from the standard one.
TEST(EstimationKalmanStatistics, PlainFilterUnderstatesItsError) {
  const MonteCarlo mc = RunMonteCarlo(estimation::CovarianceMode::kPlain);
  for (int t : {8, 22}) {
    const auto [diff, se] = MeanAndError(
        [&](int r) { return (mc.xhat[r][t] - mc.x[r][t]).squaredNorm() - mc.P[r][t].trace(); });
    EXPECT_GT(diff, 10.0 * se) << "step " << t;
  }
}

// Lemma (eq. 23): E[e z^T] = 0 for the a-posteriori error e(t) = X^(t) - X(t) and
// z(t) = X(t+1) - A X(t). Band: 4.5 standard errors per entry (9 entries, several steps).
// Control: the a-priori error of the next step, e- = A e - z, has E[e- z^T] = -E[Qz] != 0, and
// the same band detects it.
TEST(EstimationKalmanStatistics, LemmaErrorUncorrelatedWithChainNoise) {
  const MonteCarlo& mc = Extended();
  for (int t : {2, 9, 18, 27}) {
    const Eigen::MatrixXd A = OpenLoopA(ThreeStateModel(60, 0.6), t);
    for (int i = 0; i < 3; ++i) {
      for (int k = 0; k < 3; ++k) {
        const auto [mean, se] =
            MeanAndError([&](int r) { return (mc.xhat[r][t] - mc.x[r][t])(i)*mc.z[r][t](k); });
        EXPECT_LT(std::abs(mean), 4.5 * se) << "step " << t << " entry " << i << k;
      }
    }
    const auto [prior_mean, prior_se] = MeanAndError([&](int r) {
      const Eigen::VectorXd e_prior = A * (mc.xhat[r][t] - mc.x[r][t]) - mc.z[r][t];
      return e_prior(0) * mc.z[r][t](0);
    });
    EXPECT_GT(std::abs(prior_mean), 10.0 * prior_se) << "step " << t;
  }
}

// NEES e^T P^+ e (P has rank m - 1, so the pseudo-inverse). For a consistent filter the
// average over R runs, times R, is chi-square with R (m - 1) degrees of freedom. Checks: blocks
// of R = 250 runs at 7 steps (56 block means); each should fall inside its 95 % two-sided band
// (+-12 % around m - 1 = 2), so about 5 % of them fall outside by chance: at most 8 of 56 may
// (P[Binomial(56, 0.05) > 8] = 0.3 %). The plain filter (no Qz) fails the same check.
int NeesBlocksOutsideBand(const MonteCarlo& mc, double* worst) {
  constexpr int R = 250;
  const double dof = R * 2.0;
  const double lo = testing_util::ChiSquareQuantile(dof, -1.959964) / R;
  const double hi = testing_util::ChiSquareQuantile(dof, 1.959964) / R;
  int outside = 0;
  *worst = 0.0;
  for (int t : {2, 5, 10, 15, 20, 25, 29}) {
    for (int block = 0; block < kRuns / R; ++block) {
      double sum = 0;
      for (int r = block * R; r < (block + 1) * R; ++r) {
        const Eigen::MatrixXd Pinv = mc.P[r][t].completeOrthogonalDecomposition().pseudoInverse();
        const Eigen::VectorXd e = mc.xhat[r][t] - mc.x[r][t];
        sum += e.dot(Pinv * e);
      }
      const double nees = sum / R;
      if (nees < lo || nees > hi) ++outside;
      *worst = std::max(*worst, std::abs(nees - 2.0));
    }
  }
  return outside;
}

TEST(EstimationKalmanStatistics, NeesInsideChiSquareBand) {
  double worst = 0.0;
  const int outside = NeesBlocksOutsideBand(Extended(), &worst);
  std::cout << "NEES block means outside the 95 % band: " << outside << " of 56, worst |NEES - 2| "
            << worst << "\n";
  EXPECT_LE(outside, 8) << "of 56 block means; worst |NEES - 2| = " << worst;
  const int outside_plain =
      NeesBlocksOutsideBand(RunMonteCarlo(estimation::CovarianceMode::kPlain), &worst);
  std::cout << "plain filter: " << outside_plain << " of 56 outside\n";
  EXPECT_GE(outside_plain, 40) << "the plain filter's NEES should be far too large";
}

// No data (prediction only), constant A with a real spectrum (a birth-death chain): X^ -> N pi
// (eq. 29), P -> N (diag pi - pi pi^T) (eq. 30) to 1e-9, and Gamma = V^T P V stays inside the
// eq. 36 bound at every step, with Gamma_11 = 0.
TEST(EstimationKalmanStatistics, NoDataConvergesToEquilibriumInsideGammaBound) {
  Eigen::Matrix3d A;
  A << 0.7, 0.2, 0.0,  //
      0.3, 0.5, 0.4,   //
      0.0, 0.3, 0.6;
  estimation::FilterModel f = ThreeStateModel(60, 0.6);
  f.transition = estimation::TransitionSource::kConstant;
  f.A = A;
  auto pi = estimation::StationaryDistribution(A);
  ASSERT_TRUE(pi.ok());
  const Eigen::MatrixXd Peq = estimation::EquilibriumCovariance(*pi, 60);
  auto gb = estimation::ComputeGammaBound(A, estimation::ConservativeQz(A, 60));
  ASSERT_TRUE(gb.ok()) << gb.error();
  for (estimation::CovarianceMode mode :
       {estimation::CovarianceMode::kExtended, estimation::CovarianceMode::kConservative}) {
    auto kf = estimation::PopulationKalmanFilter::Create(f, mode);
    ASSERT_TRUE(kf.ok());
    double tightest = 0.0;
    for (int t = 0; t < 300; ++t) {
      kf->Predict(A);
      const Eigen::MatrixXd G = gb->Gamma(kf->covariance());
      EXPECT_NEAR(G(0, 0), 0.0, 1e-9);
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
          if (i == 0 && j == 0) continue;
          ASSERT_LE(std::abs(G(i, j)), gb->bound(i, j) + 1e-9)
              << ToString(mode) << " step " << t << " (" << i << ", " << j << ")";
          tightest = std::max(tightest, std::abs(G(i, j)) / gb->bound(i, j));
        }
      }
    }
    if (mode == estimation::CovarianceMode::kExtended) {
      EXPECT_LT((kf->estimate() - 60.0 * *pi).cwiseAbs().maxCoeff(), 1e-9);
      EXPECT_LT((kf->covariance() - Peq).cwiseAbs().maxCoeff(), 1e-9);
      // Eq. 34 at its fixed point: Gamma_ij = e_i^T Qz(N pi) e_j / (1 - lambda_i lambda_j).
      const Eigen::MatrixXd VQV =
          gb->V.transpose() * estimation::ProcessCovarianceQz(A, 60.0 * *pi) * gb->V;
      const Eigen::MatrixXd G = gb->Gamma(kf->covariance());
      for (int i = 1; i < 3; ++i) {
        for (int j = 1; j < 3; ++j) {
          EXPECT_NEAR(G(i, j), VQV(i, j) / (1.0 - gb->lambda(i) * gb->lambda(j)), 1e-9);
        }
      }
    } else {
      // The conservative covariance dominates the equilibrium one.
      EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(kf->covariance() - Peq)
                    .eigenvalues()
                    .minCoeff(),
                -1e-9);
    }
    EXPECT_GT(tightest, 0.2) << "the bound is not vacuous";
  }
}

// 10^6 steps of a simulated chain, m = 4, r = 2, process noise, changing A, every fifth
// measurement missing: the estimate keeps summing to N within 1e-9, P stays symmetric, PSD and
// with zero column sums (1^T K = 0 keeps the total).
TEST(EstimationKalmanStatistics, MillionStepsKeepSumSymmetryAndPsd) {
  estimation::FilterModel f;
  f.state_names = {"a", "b", "c", "d"};
  f.N = 500;
  f.H.resize(2, 4);
  f.H << 0.0, 0.1, 0.3, 0.45, 1.0, 0.5, 0.0, 0.2;
  f.R = Eigen::Matrix2d{{0.5, 0.1}, {0.1, 0.8}};
  f.G = Eigen::Vector4d(0.0, 1.0, -1.0, 0.0);
  f.Qw = Eigen::MatrixXd::Constant(1, 1, 0.3);
  f.transition = estimation::TransitionSource::kExplicit;
  f.x0 = Eigen::Vector4d(500, 0, 0, 0);
  f.P0 = Eigen::Matrix4d::Zero();
  Rng rng(99);
  std::vector<Eigen::MatrixXd> pool;
  for (int k = 0; k < 16; ++k) {
    Eigen::MatrixXd A(4, 4);
    for (int j = 0; j < 4; ++j) {
      for (int i = 0; i < 4; ++i) A(i, j) = 0.05 + rng.Uniform();
      A.col(j) /= A.col(j).sum();
    }
    pool.push_back(A);
  }
  auto kf = estimation::PopulationKalmanFilter::Create(f, estimation::CovarianceMode::kExtended);
  ASSERT_TRUE(kf.ok());
  Eigen::VectorXd x = f.x0;
  double worst_sum = 0.0, worst_colsum = 0.0, worst_eig = 0.0;
  for (int t = 0; t < 1000000; ++t) {
    const Eigen::MatrixXd& A = pool[t % 16];
    kf->Predict(A);
    x = estimation::SimulateStepAggregate(A, x, rng);
    if (t % 5 != 0) kf->Update(f.H * x + Eigen::Vector2d(rng.Uniform() - 0.5, rng.Uniform() - 0.5));
    worst_sum = std::max(worst_sum, std::abs(kf->estimate().sum() - 500.0));
    if (t % 1000 == 0) {
      const Eigen::MatrixXd& P = kf->covariance();
      ASSERT_EQ(P, P.transpose());
      worst_colsum = std::max(worst_colsum, P.colwise().sum().cwiseAbs().maxCoeff());
      worst_eig = std::min(
          worst_eig,
          Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(P).eigenvalues().minCoeff() / P.trace());
    }
  }
  EXPECT_LT(worst_sum, 1e-9);
  EXPECT_LT(worst_colsum, 1e-9);
  EXPECT_GT(worst_eig, -1e-12);
  EXPECT_TRUE(kf->estimate().allFinite());
}

}  // namespace file_kalman_statistics_test
}  // namespace recruit
