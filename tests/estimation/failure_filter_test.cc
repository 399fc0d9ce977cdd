// The filter with absorbing failed states (estimation/failure_filter.h): bit-identical to the
// paper's filter while nothing is declared; the augmented chain's mean and Qz against an exact
// enumeration of every unit's moves for small N; detection of an abrupt loss on simulated data.
#include "estimation/failure_filter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <vector>

#include "common/rng.h"
#include "estimation/population_chain.h"

namespace recruit {
namespace {

// An 8-state heating chain with a force per state (0.45 N settled on), N units, noise 0.2 N.
FilterModel ChainModel(int N, double noise = 0.2) {
  FilterModel f;
  f.broadcast = BroadcastTransitionModel::HeatingChain(8, 0.5);
  f.state_names = f.broadcast.state_names;
  f.N = N;
  f.H = Eigen::MatrixXd(1, 8);
  f.H << 0, 0.1, 0.25, 0.4, 0.45, 0.3, 0.15, 0.05;
  f.R = Eigen::MatrixXd::Constant(1, 1, noise * noise);
  f.G = Eigen::MatrixXd::Zero(8, 0);
  f.Qw = Eigen::MatrixXd::Zero(0, 0);
  f.transition = TransitionSource::kBroadcast;
  f.x0 = Eigen::VectorXd::Zero(8);
  f.x0[0] = N;
  f.P0 = Eigen::MatrixXd::Zero(8, 8);
  return f;
}

// A controller-like broadcast sequence: recruit towards a target that changes every 20 steps.
struct Drive {
  Rng rng{17};
  double target = 0;
  void Next(int k, double on, double N, double* p_on, double* p_off) {
    if (k % 20 == 0) target = N * (0.2 + 0.6 * rng.Uniform());
    const double e = target - on;
    *p_on = e > 0 ? std::min(1.0, 0.3 * e / std::max(1.0, N - on)) : 0;
    *p_off = e < 0 ? std::min(1.0, -0.3 * e / std::max(1.0, on)) : 0;
  }
};

TEST(EstimationFailureFilter, WithoutDeclarationItIsThePapersFilterBitForBit) {
  const FilterModel model = ChainModel(60);
  auto plain = PopulationKalmanFilter::Create(model, CovarianceMode::kExtended);
  auto aug = FailureKalmanFilter::Create(model, CovarianceMode::kExtended, {});
  ASSERT_TRUE(plain.ok() && aug.ok());
  Rng rng(3);
  Eigen::VectorXd x = model.x0;
  Drive drive;
  for (int k = 0; k < 400; ++k) {
    Eigen::VectorXd y(1);
    y[0] = model.H.row(0).dot(x) + 0.2 * std::sqrt(-2 * std::log(1 - rng.Uniform())) *
                                       std::cos(6.283185307179586 * rng.Uniform());
    plain->Update(y);
    aug->Update(y[0]);
    ASSERT_EQ(aug->declarations(), 0) << k;
    ASSERT_TRUE((aug->working_filter().estimate().array() == plain->estimate().array()).all());
    ASSERT_TRUE((aug->working_filter().covariance().array() == plain->covariance().array()).all());
    double on = 0;
    for (int j = 0; j < 8; ++j) on += model.broadcast.is_on[j] ? plain->estimate()[j] : 0;
    double p_on, p_off;
    drive.Next(k, on, 60, &p_on, &p_off);
    plain->PredictBroadcast(p_on, p_off);
    aug->PredictBroadcast(p_on, p_off);
    x = SimulateStepAggregate(model.broadcast.Matrix(p_on, p_off), x, rng);
  }
  EXPECT_FALSE(aug->augmented());
  EXPECT_EQ(aug->working(), 60);
}

// Exact moments of X(t + k) by enumerating every unit's path: each unit moves independently by
// the augmented A, so X is a sum of independent one-unit categorical vectors.
void EnumerateMoments(const std::vector<Eigen::MatrixXd>& steps, const std::vector<int>& units,
                      int n, Eigen::VectorXd* mean, Eigen::MatrixXd* cov) {
  // Joint distribution over all units' final states, by full enumeration of the product space.
  const int N = static_cast<int>(units.size());
  *mean = Eigen::VectorXd::Zero(n);
  Eigen::MatrixXd second = Eigen::MatrixXd::Zero(n, n);
  std::vector<int> path(N * steps.size(), 0);
  std::function<void(int, double, std::vector<int>&)> rec = [&](int pos, double prob,
                                                                std::vector<int>& cur) {
    if (prob == 0) return;
    if (pos == static_cast<int>(path.size())) {
      Eigen::VectorXd X = Eigen::VectorXd::Zero(n);
      for (int u = 0; u < N; ++u) X[cur[u]] += 1;
      *mean += prob * X;
      second += prob * X * X.transpose();
      return;
    }
    const int u = pos % N;
    const Eigen::MatrixXd& A = steps[pos / N];
    const int from = cur[u];
    for (int to = 0; to < n; ++to) {
      cur[u] = to;
      rec(pos + 1, prob * A(to, from), cur);
    }
    cur[u] = from;
  };
  std::vector<int> cur = units;
  rec(0, 1.0, cur);
  *cov = second - *mean * mean->transpose();
}

TEST(EstimationFailureFilter, AugmentedChainMeanAndQzMatchExactEnumeration) {
  const FilterModel model = ChainModel(3);
  const std::vector<Eigen::MatrixXd> steps = {
      AugmentedTransition(model.broadcast, 0.6, 0.0, 0.1, 0.05),
      AugmentedTransition(model.broadcast, 0.0, 0.3, 0.1, 0.05)};
  const std::vector<int> units = {0, 2, 4};  // one off, two heated
  const int n = 24;                          // working, open, stuck: 8 states each
  Eigen::VectorXd x0 = Eigen::VectorXd::Zero(n);
  for (int u : units) x0[u] += 1;
  // One step: E = A X, Cov = Qz(X) (eq. 25 on the augmented chain).
  Eigen::VectorXd mean;
  Eigen::MatrixXd cov;
  EnumerateMoments({steps[0]}, units, n, &mean, &cov);
  EXPECT_LT((mean - steps[0] * x0).norm(), 1e-12);
  EXPECT_LT((cov - ProcessCovarianceQz(steps[0], x0)).norm(), 1e-12);
  // Two steps: E = A2 A1 X, Cov = A2 Qz(X) A2^T + Qz(A1 X) (the filter's recursion from P = 0,
  // exact because Qz is linear in X).
  EnumerateMoments(steps, units, n, &mean, &cov);
  EXPECT_LT((mean - steps[1] * steps[0] * x0).norm(), 1e-12);
  const Eigen::MatrixXd P2 = steps[1] * ProcessCovarianceQz(steps[0], x0) * steps[1].transpose() +
                             ProcessCovarianceQz(steps[1], steps[0] * x0);
  EXPECT_LT((cov - P2).norm(), 1e-12);
  // Failed classes absorb (no way back to the working states) and ignore broadcasts (their
  // block is the chain's interior); every column is stochastic.
  EXPECT_EQ(steps[0].block(0, 8, 8, 16).norm(), 0);
  EXPECT_EQ(steps[0].block(8, 8, 8, 8), model.broadcast.interior);
  for (int j = 0; j < n; ++j) EXPECT_NEAR(steps[0].col(j).sum(), 1, 1e-15);
  // A heated unit failing open enters the cooling state of its temperature.
  EXPECT_EQ(steps[0](8 + model.broadcast.off_target[2], 2), 0.1);
}

// Prior hazards alone (no detection): with no data the filter's mean working count follows
// the closed form of a pure-death process on the heated units.
TEST(EstimationFailureFilter, PriorHazardDepletesTheHeatedUnitsAsExpected) {
  FilterModel model = ChainModel(50);
  FailureFilterParams p;
  p.open_hazard = 0.01;
  p.detect = false;
  auto f = FailureKalmanFilter::Create(model, CovarianceMode::kExtended, p);
  ASSERT_TRUE(f.ok());
  // Settle every unit in the hot state (state 4 of the chain) first by broadcasting p_on = 1.
  f->PredictBroadcast(1, 0);
  for (int k = 0; k < 60; ++k) f->PredictBroadcast(0, 0);
  // Units fail at 0.01 per step from heated states only: the first step starts from the off
  // state 0, the next 60 from heated ones, so working = 50 (0.99)^60.
  EXPECT_NEAR(f->working(), 50 * std::pow(0.99, 60), 1e-9);
  EXPECT_GT(f->working_variance(), 0);
}

// Simulated plant: an aggregate chain, 10 % of the units (chosen at random) fail open at step
// 150; no declaration before, and a declared loss brings the working count within 2 units in 10
// steps.
TEST(EstimationFailureFilter, AbruptLossIsFoundWithinTenInstants) {
  const int N = 60, lost = 6;
  const FilterModel model = ChainModel(N, 0.1);
  int good = 0, declared = 0;
  const int seeds = 10;
  for (int seed = 0; seed < seeds; ++seed) {
    auto f = FailureKalmanFilter::Create(model, CovarianceMode::kExtended, {});
    ASSERT_TRUE(f.ok());
    Rng rng(1000 + seed);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(24);
    x[0] = N;
    Drive drive;
    int caught = -1;
    for (int k = 0; k < 200; ++k) {
      if (k == 150) {  // `lost` units drawn without replacement from the working ones
        for (int u = 0; u < lost; ++u) {
          double pick = rng.Uniform() * x.head(8).sum();
          int j = 0;
          while (pick >= x[j]) pick -= x[j++];
          x[j] -= 1;
          x[8 + OpenEntry(model.broadcast, j)] += 1;
        }
      }
      const double force = model.H.row(0).dot(x.head(8) + x.segment(8, 8) + x.tail(8));
      f->Update(force + 0.1 * std::sqrt(-2 * std::log(1 - rng.Uniform())) *
                            std::cos(6.283185307179586 * rng.Uniform()));
      const double truth = x.head(8).sum();
      if (k >= 150 && caught < 0 && std::abs(f->working() - truth) <= 2) caught = k - 150;
      if (k < 150) {
        EXPECT_EQ(f->declarations(), 0) << "seed " << seed << " k " << k;
      }
      double on = 0;
      const Eigen::VectorXd e = f->estimate();
      for (int j = 0; j < 8; ++j) on += model.broadcast.is_on[j] ? e[j] : 0;
      double p_on, p_off;
      drive.Next(k, on, N, &p_on, &p_off);
      f->PredictBroadcast(p_on, p_off);
      x = SimulateStepAggregate(AugmentedTransition(model.broadcast, p_on, p_off, 0, 0), x, rng);
    }
    // A declared loss is placed: within 2 units in 10 instants. An undeclared one (few of the
    // lost units were heated, so the force hardly changed) leaves the estimate at N.
    if (f->declarations() > 0) {
      ++declared;
      EXPECT_TRUE(caught >= 0 && caught <= 10) << "seed " << seed << ": " << caught;
    }
    if (caught >= 0 && caught <= 10) ++good;
  }
  std::printf("abrupt loss declared in %d and found within 10 instants in %d of %d seeds\n",
              declared, good, seeds);
  EXPECT_GE(declared, seeds / 2);
}

}  // namespace
}  // namespace recruit
