// The population chain: validation, exact samplers, Qz (eq. 25), pi and the equilibrium
// covariance (eqs. 29-30), checked against closed forms and Monte Carlo with stated bands.
#include "estimation/population_chain.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "test_util.h"

namespace recruit {
namespace file_population_chain_test {

Eigen::Matrix3d A3() {
  Eigen::Matrix3d A;
  A << 0.7, 0.2, 0.1,  //
      0.2, 0.5, 0.3,   //
      0.1, 0.3, 0.6;
  return A;
}

TEST(EstimationChain, ValidationNamesColumnEntryAndTolerance) {
  Eigen::Matrix3d A = A3();
  EXPECT_TRUE(estimation::ValidateColumnStochastic(A).ok());
  A(1, 2) = 0.35;  // column 2 sums to 1.05
  Status s = estimation::ValidateColumnStochastic(A);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().find("column 2 sums to 1.05"), std::string::npos) << s.error();
  EXPECT_NE(s.error().find("tolerance 1e-09"), std::string::npos) << s.error();
  A = A3();
  A(0, 1) = -0.1;
  A(1, 1) = 0.8;
  s = estimation::ValidateColumnStochastic(A);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().find("entry (0, 1) = -0.1"), std::string::npos) << s.error();
  A = A3();
  A(2, 0) = NAN;
  s = estimation::ValidateColumnStochastic(A);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().find("entry (2, 0) is not finite"), std::string::npos) << s.error();
  s = estimation::ValidateColumnStochastic(Eigen::MatrixXd::Constant(2, 3, 0.5));
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().find("must be square"), std::string::npos) << s.error();
  s = estimation::ValidateColumnStochastic(A3(), estimation::kStochasticTolerance, 2, "m.json: A");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().find("m.json: A: must be 2 x 2"), std::string::npos) << s.error();
  // Within the tolerance is accepted.
  A = A3();
  A(0, 0) += 5e-10;
  EXPECT_TRUE(estimation::ValidateColumnStochastic(A).ok());
}

TEST(EstimationChain, CountValidation) {
  EXPECT_TRUE(estimation::ValidateCounts(Eigen::Vector3d(20, 30, 10), 3, 60).ok());
  Status s = estimation::ValidateCounts(Eigen::Vector3d(-2, 52, 10), 3, 60);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().find("entry 0 = -2 is negative"), std::string::npos) << s.error();
  EXPECT_FALSE(estimation::ValidateCounts(Eigen::Vector3d(20.5, 29.5, 10), 3, 60).ok());
  EXPECT_FALSE(estimation::ValidateCounts(Eigen::Vector3d(20, 30, 11), 3, 60).ok());
  EXPECT_FALSE(estimation::ValidateCounts(Eigen::Vector2d(30, 30), 3, 60).ok());
}

// Pearson chi-square of 2e5 binomial draws against the pmf, bins pooled to >= 20 expected.
// Band: the 1 - 3e-5 quantile (z = 4) of chi-square with (bins - 1) degrees of freedom.
TEST(EstimationChain, BinomialSamplerMatchesPmf) {
  struct Case {
    int64_t n;
    double p;
  };
  // Inversion (n p < 15), rejection (n p >= 15) and the p > 1/2 reflection.
  for (const Case c : {Case{10, 0.3}, Case{60, 0.05}, Case{200, 0.4}, Case{1000, 0.97}}) {
    Rng rng(1234 + c.n);
    const int draws = 200000;
    std::vector<double> hist(c.n + 1, 0.0);
    for (int k = 0; k < draws; ++k) hist[estimation::SampleBinomial(c.n, c.p, rng)] += 1.0;
    double chi2 = 0.0, exp_acc = 0.0, obs_acc = 0.0;
    int bins = 0;
    for (int64_t k = 0; k <= c.n; ++k) {
      const double lp = std::lgamma(c.n + 1.0) - std::lgamma(k + 1.0) - std::lgamma(c.n - k + 1.0) +
                        k * std::log(c.p) + (c.n - k) * std::log1p(-c.p);
      exp_acc += draws * std::exp(lp);
      obs_acc += hist[k];
      if (exp_acc >= 20.0 || k == c.n) {
        chi2 += (obs_acc - exp_acc) * (obs_acc - exp_acc) / exp_acc;
        exp_acc = obs_acc = 0.0;
        ++bins;
      }
    }
    EXPECT_LT(chi2, testing_util::ChiSquareQuantile(bins - 1, 4.0))
        << "n = " << c.n << ", p = " << c.p << ", bins = " << bins;
  }
}

// Sample mean and covariance of z = X(t+1) - A X(t) against E[z] = 0 and Qz (eq. 25).
// Band per entry: 5 standard errors, estimated from the same draws (the fourth moments).
void CheckAgainstQz(const std::vector<Eigen::VectorXd>& next, const Eigen::MatrixXd& A,
                    const Eigen::VectorXd& x) {
  const int m = static_cast<int>(x.size());
  const double n = static_cast<double>(next.size());
  const Eigen::VectorXd mean_expected = A * x;
  const Eigen::MatrixXd Qz = estimation::ProcessCovarianceQz(A, x);
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(m);
  Eigen::MatrixXd S1 = Eigen::MatrixXd::Zero(m, m), S2 = Eigen::MatrixXd::Zero(m, m);
  for (const auto& xn : next) {
    const Eigen::VectorXd z = xn - mean_expected;  // exact centring: E[z] = 0 under the model
    mean += z;
    const Eigen::MatrixXd zz = z * z.transpose();
    S1 += zz;
    S2 += zz.cwiseProduct(zz);
  }
  mean /= n;
  const Eigen::MatrixXd cov = S1 / n;
  const Eigen::MatrixXd se = ((S2 / n - cov.cwiseProduct(cov)) / n).cwiseSqrt();
  for (int i = 0; i < m; ++i) {
    EXPECT_LT(std::abs(mean(i)), 5.0 * std::sqrt(Qz(i, i) / n)) << "mean " << i;
    for (int k = 0; k < m; ++k) {
      EXPECT_LT(std::abs(cov(i, k) - Qz(i, k)), 5.0 * se(i, k))
          << "(" << i << ", " << k << "): sample " << cov(i, k) << ", Qz " << Qz(i, k);
    }
  }
  // The band is tight enough to tell Qz from the plain binomial variances diag(A X): the
  // off-diagonal entries of Qz are several standard errors from zero.
  EXPECT_GT(std::abs(Qz(0, 1)), 10.0 * se(0, 1));
}

TEST(EstimationChain, AggregateSamplerCovarianceIsQz) {
  const Eigen::Matrix3d A = A3();
  const Eigen::Vector3d x(20, 30, 10);
  Rng rng(7);
  std::vector<Eigen::VectorXd> next;
  for (int k = 0; k < 100000; ++k) {
    next.push_back(estimation::SimulateStepAggregate(A, x, rng));
    ASSERT_EQ(next.back().sum(), 60.0);
  }
  CheckAgainstQz(next, A, x);
}

TEST(EstimationChain, AgentSamplerCovarianceIsQz) {
  const Eigen::Matrix3d A = A3();
  std::vector<int> states;
  for (int i = 0; i < 20; ++i) states.push_back(0);
  for (int i = 0; i < 30; ++i) states.push_back(1);
  for (int i = 0; i < 10; ++i) states.push_back(2);
  const Eigen::VectorXd x = estimation::CountStates(states, 3);
  Rng rng(8);
  std::vector<Eigen::VectorXd> next;
  for (int k = 0; k < 100000; ++k) {
    std::vector<int> s = states;
    next.push_back(estimation::SimulateStepAgents(A, s, rng));
  }
  CheckAgainstQz(next, A, x);
}

TEST(EstimationChain, AggregateSamplerCostDoesNotGrowWithN) {
  // Exactness at a large N (the O(1) binomial path): mean and variance of one count.
  const Eigen::Matrix2d A{{0.9, 0.3}, {0.1, 0.7}};
  const Eigen::Vector2d x(4e6, 6e6);
  Rng rng(9);
  const int draws = 20000;
  double s1 = 0, s2 = 0;
  for (int k = 0; k < draws; ++k) {
    const double v = estimation::SimulateStepAggregate(A, x, rng)(1) - (A * x)(1);
    s1 += v;
    s2 += v * v;
  }
  const double var = estimation::ProcessCovarianceQz(A, x)(1, 1);  // 4e6*0.09 + 6e6*0.21
  EXPECT_LT(std::abs(s1 / draws), 5.0 * std::sqrt(var / draws));
  EXPECT_NEAR(s2 / draws, var, 5.0 * var * std::sqrt(2.0 / draws));
}

TEST(EstimationChain, StationaryDistributionAndEquilibriumCovariance) {
  // Two-state chain: pi = (p_off, p_on) / (p_on + p_off).
  const double p_on = 0.3, p_off = 0.1;
  const Eigen::Matrix2d A{{1 - p_on, p_off}, {p_on, 1 - p_off}};
  auto pi = estimation::StationaryDistribution(A);
  ASSERT_TRUE(pi.ok()) << pi.error();
  EXPECT_NEAR((*pi)(0), 0.25, 1e-15);
  EXPECT_NEAR((*pi)(1), 0.75, 1e-15);
  const Eigen::MatrixXd C = estimation::EquilibriumCovariance(*pi, 60);
  EXPECT_NEAR(C(0, 0), 60 * 0.25 * 0.75, 1e-12);  // binomial variance
  EXPECT_NEAR(C(0, 1), -60 * 0.25 * 0.75, 1e-12);
  // Three states: A pi = pi, sum 1.
  auto pi3 = estimation::StationaryDistribution(A3());
  ASSERT_TRUE(pi3.ok());
  EXPECT_LT((A3() * *pi3 - *pi3).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_NEAR(pi3->sum(), 1.0, 1e-14);
  // Reducible chain: no unique pi.
  EXPECT_FALSE(estimation::StationaryDistribution(Eigen::Matrix2d::Identity()).ok());
}

TEST(EstimationChain, ConservativeQzDominatesEveryAdmissibleQz) {
  const Eigen::Matrix3d A = A3();
  const Eigen::MatrixXd Qc = estimation::ConservativeQz(A, 60);
  Rng rng(10);
  for (int k = 0; k < 200; ++k) {
    // Random admissible X (sum N) and box corners.
    Eigen::Vector3d x(rng.Uniform(), rng.Uniform(), rng.Uniform());
    x = (x / x.sum() * 60).array().round();
    x(2) = 60 - x(0) - x(1);
    if (x(2) < 0) continue;
    const Eigen::MatrixXd D = Qc - estimation::ProcessCovarianceQz(A, x);
    EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(D).eigenvalues().minCoeff(), -1e-10);
  }
}

TEST(EstimationChain, SimplexProjectionIsTheNearestFeasiblePoint) {
  Rng rng(11);
  for (int k = 0; k < 100; ++k) {
    Eigen::VectorXd x(4);
    for (int i = 0; i < 4; ++i) x(i) = 30.0 * (rng.Uniform() - 0.3);
    const Eigen::VectorXd p = estimation::ProjectOntoSimplex(x, 40.0);
    ASSERT_GE(p.minCoeff(), 0.0);
    ASSERT_NEAR(p.sum(), 40.0, 1e-9);
    // No random feasible point is nearer.
    for (int t = 0; t < 200; ++t) {
      Eigen::VectorXd q(4);
      for (int i = 0; i < 4; ++i) q(i) = -std::log(1.0 - rng.Uniform());
      q *= 40.0 / q.sum();
      EXPECT_LE((p - x).norm(), (q - x).norm() + 1e-12);
    }
  }
}

TEST(EstimationChain, CountStateVectors) {
  EXPECT_EQ(estimation::CountStateVectors(60, 2), 61u);
  EXPECT_EQ(estimation::CountStateVectors(60, 3), 1891u);                   // C(62, 2)
  EXPECT_EQ(estimation::CountStateVectors(60, 20), 883829035553043580ull);  // C(79, 19)
  EXPECT_EQ(estimation::CountStateVectors(1000, 10, 200000), 200001u);      // saturates
}

}  // namespace file_population_chain_test
}  // namespace recruit
