// The exact Bayesian filter and the particle filter: closed forms for one step, the refusal of
// huge state spaces, and the accuracy comparison with the population Kalman filter on N = 60.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "estimation/exact_filter.h"
#include "estimation/particle_filter.h"
#include "estimation/population_chain.h"
#include "estimation/population_kalman_filter.h"
#include "test_util.h"

namespace recruit {
namespace file_baselines_test {

using testing_util::ThreeStateModel;

// One prediction from a point mass: the exact belief is the convolution of the columns'
// multinomials, whose mean is A X and covariance Qz(X) (eq. 25).
TEST(EstimationExact, PredictionFromPointMassHasMeanAXAndCovarianceQz) {
  estimation::FilterModel f = ThreeStateModel(20, 0.5);
  f.x0 = Eigen::Vector3d(8, 5, 7);
  auto ex = estimation::ExactBayesFilter::Create(f);
  ASSERT_TRUE(ex.ok()) << ex.error();
  EXPECT_EQ(ex->num_count_vectors(), 231u);  // C(22, 2)
  Eigen::Matrix3d A;
  A << 0.7, 0.2, 0.1, 0.2, 0.5, 0.3, 0.1, 0.3, 0.6;
  ex->Predict(A);
  EXPECT_LT((ex->Mean() - A * f.x0).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((ex->Covariance() - estimation::ProcessCovarianceQz(A, f.x0)).cwiseAbs().maxCoeff(),
            1e-12);
  double total = 0;
  for (double p : ex->probabilities()) total += p;
  EXPECT_NEAR(total, 1.0, 1e-12);
}

// Two states from all-off: X_on(1) ~ Binomial(N, p_on); the posterior after y is
// Bin(k; N, p_on) exp(-(y - h k)^2 / 2R) normalised, computed here from the pmf directly.
TEST(EstimationExact, UpdateIsBayesRuleOnTheBinomial) {
  const int N = 30;
  const double p_on = 0.3, h = 0.45, sd = 0.5, y = 5.0;
  const estimation::FilterModel f = estimation::FilterModel::TwoState(N, 0.5, h, sd);
  auto ex = estimation::ExactBayesFilter::Create(f);
  ASSERT_TRUE(ex.ok());
  ex->Predict(f.broadcast.Matrix(p_on, 0.1));
  ex->Update(Eigen::VectorXd::Constant(1, y));
  double z = 0, m1 = 0, m2 = 0;
  for (int k = 0; k <= N; ++k) {
    const double w =
        std::exp(std::lgamma(N + 1.0) - std::lgamma(k + 1.0) - std::lgamma(N - k + 1.0) +
                 k * std::log(p_on) + (N - k) * std::log(1 - p_on) -
                 (y - h * k) * (y - h * k) / (2 * sd * sd));
    z += w;
    m1 += w * k;
    m2 += w * k * k;
  }
  const double mean = m1 / z, var = m2 / z - mean * mean;
  EXPECT_NEAR(ex->Mean()(1), mean, 1e-10);
  EXPECT_NEAR(ex->Mean()(0), N - mean, 1e-10);
  EXPECT_NEAR(ex->Covariance()(1, 1), var, 1e-10);
}

TEST(EstimationExact, RefusesHugeStateSpaces) {
  estimation::FilterModel f = ThreeStateModel(1000, 0.5);  // C(1002, 2) = 501501 count vectors
  auto ex = estimation::ExactBayesFilter::Create(f);
  ASSERT_FALSE(ex.ok());
  EXPECT_NE(ex.error().find("more than 200000 count vectors"), std::string::npos) << ex.error();
  estimation::ExactFilterOptions big;
  big.max_states = 600000;
  big.cache_bytes = 0;  // no S x S table: rows on the fly
  EXPECT_TRUE(estimation::ExactBayesFilter::Create(f, big).ok());
}

// Paired Monte Carlo comparison on N = 60: the same simulated runs filtered by the extended
// Kalman filter, the exact Bayesian filter and particle filters. RMSE over all runs and steps.
struct Comparison {
  double rmse_kalman = 0, rmse_exact = 0;
  std::vector<double> rmse_particle, dist_particle;  // per particle count; dist: |PF - exact|^2
};

Comparison Compare(const estimation::FilterModel& f, int runs, int steps,
                   const std::vector<int>& particles) {
  Comparison c;
  c.rmse_particle.assign(particles.size(), 0.0);
  c.dist_particle.assign(particles.size(), 0.0);
  auto exact = estimation::ExactBayesFilter::Create(f);  // one filter: its tables are cached per A
  EXPECT_TRUE(exact.ok()) << exact.error();
  const std::vector<double> prior = exact->probabilities();
  for (int run = 0; run < runs; ++run) {
    Rng rng(Rng::DeriveSeed(77, run));
    auto kf = estimation::PopulationKalmanFilter::Create(f, estimation::CovarianceMode::kExtended);
    estimation::ExactBayesFilter& ex = *exact;
    EXPECT_TRUE(ex.SetProbabilities(prior).ok());  // back to the prior, keeping the tables
    std::vector<estimation::ParticleFilter> pfs;
    std::vector<Rng> pf_rngs;
    for (size_t k = 0; k < particles.size(); ++k) {
      pf_rngs.emplace_back(Rng::DeriveSeed(1000 + run, k));
      pfs.push_back(*estimation::ParticleFilter::Create(f, {particles[k], 0.5}, pf_rngs.back()));
    }
    Eigen::VectorXd x = f.x0;
    for (int t = 0; t < steps; ++t) {
      // Piecewise-constant open-loop broadcast: recruit, hold, release (three distinct A).
      const int phase = (t / 10) % 3;
      const Eigen::MatrixXd A = f.broadcast.Matrix(phase == 0 ? 0.25 : (phase == 1 ? 0.05 : 0.02),
                                                   phase == 0 ? 0.02 : (phase == 1 ? 0.05 : 0.2));
      const Eigen::VectorXd y = testing_util::Measure(f, x, rng);
      kf->Update(y);
      ex.Update(y);
      const Eigen::VectorXd xe = ex.Mean();
      c.rmse_kalman += (kf->estimate() - x).squaredNorm();
      c.rmse_exact += (xe - x).squaredNorm();
      for (size_t k = 0; k < pfs.size(); ++k) {
        pfs[k].Update(y, pf_rngs[k]);
        c.rmse_particle[k] += (pfs[k].Mean() - x).squaredNorm();
        c.dist_particle[k] += (pfs[k].Mean() - xe).squaredNorm();
        pfs[k].Predict(A, pf_rngs[k]);
      }
      kf->Predict(A);
      ex.Predict(A);
      x = estimation::SimulateStepAggregate(A, x, rng);
    }
  }
  const double n = static_cast<double>(runs) * steps;
  c.rmse_kalman = std::sqrt(c.rmse_kalman / n);
  c.rmse_exact = std::sqrt(c.rmse_exact / n);
  for (size_t k = 0; k < particles.size(); ++k) {
    c.rmse_particle[k] = std::sqrt(c.rmse_particle[k] / n);
    c.dist_particle[k] /= n;
  }
  return c;
}

// m = 2, N = 60: the extended filter's RMSE within 5 % of the exact filter's; the particle
// filter's mean converges to the exact posterior mean as the particles grow (mean squared
// distance falling roughly as 1 / particles) and its RMSE approaches the exact one.
TEST(EstimationBaselines, TwoStatesKalmanWithinFivePercentOfExactAndParticlesConverge) {
  const estimation::FilterModel f = estimation::FilterModel::TwoState(60, 0.5, 0.45, 0.6);
  const Comparison c = Compare(f, 100, 30, {20, 200, 2000});
  std::cout << "m = 2: RMSE Kalman " << c.rmse_kalman << ", exact " << c.rmse_exact
            << ", particles 20/200/2000 " << c.rmse_particle[0] << " / " << c.rmse_particle[1]
            << " / " << c.rmse_particle[2] << "; |PF - exact|^2 " << c.dist_particle[0] << " / "
            << c.dist_particle[1] << " / " << c.dist_particle[2] << "\n";
  EXPECT_LT(std::abs(c.rmse_kalman / c.rmse_exact - 1.0), 0.05);
  EXPECT_LE(c.rmse_exact, c.rmse_kalman * 1.001);  // the exact posterior mean is MMSE-optimal
  EXPECT_LT(c.dist_particle[1], c.dist_particle[0] / 4.0);
  EXPECT_LT(c.dist_particle[2], c.dist_particle[1] / 4.0);
  EXPECT_LT(std::abs(c.rmse_particle[2] / c.rmse_exact - 1.0),
            std::abs(c.rmse_particle[0] / c.rmse_exact - 1.0) + 1e-3);
  EXPECT_LT(std::abs(c.rmse_particle[2] / c.rmse_exact - 1.0), 0.02);
}

// m = 3 (off, warming, on), N = 60: 1891 count vectors.
TEST(EstimationBaselines, ThreeStatesKalmanWithinFivePercentOfExact) {
  const estimation::FilterModel f = ThreeStateModel(60, 0.6);
  const Comparison c = Compare(f, 30, 30, {200});
  std::cout << "m = 3: RMSE Kalman " << c.rmse_kalman << ", exact " << c.rmse_exact
            << ", particles 200 " << c.rmse_particle[0] << "\n";
  EXPECT_LT(std::abs(c.rmse_kalman / c.rmse_exact - 1.0), 0.05);
  EXPECT_LE(c.rmse_exact, c.rmse_kalman * 1.001);
}

}  // namespace file_baselines_test
}  // namespace recruit
