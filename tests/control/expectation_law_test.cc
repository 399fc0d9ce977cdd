// The expectation law against hand-worked values (docs/controller.md):
//   recruit: p_on = lambda (target - est) / (N - est); release: p_off = lambda (est - target) /
//   est.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "control/broadcast.h"

namespace recruit::control {
namespace file_expectation_law_test {

TEST(ExpectationLaw, RecruitsLambdaTimesMissingUnitsFromTheOffUnits) {
  // N = 60, 20 on, target 30: 10 missing, 40 off, lambda 0.2 -> 0.2 * 10 / 40 = 0.05.
  Broadcast b = ExpectationLaw(30, 20, 60, 0.2);
  EXPECT_DOUBLE_EQ(b.p_on, 0.05);
  EXPECT_DOUBLE_EQ(b.p_off, 0);
  // Expected recruits = p_on * off = lambda * missing.
  EXPECT_DOUBLE_EQ(b.p_on * (60 - 20), 0.2 * 10);
}

TEST(ExpectationLaw, ReleasesLambdaTimesExcessUnitsFromTheOnUnits) {
  // 50 on, target 10: 40 excess, lambda 0.5 -> 0.5 * 40 / 50 = 0.4.
  Broadcast b = ExpectationLaw(10, 50, 60, 0.5);
  EXPECT_DOUBLE_EQ(b.p_on, 0);
  EXPECT_DOUBLE_EQ(b.p_off, 0.4);
}

TEST(ExpectationLaw, FractionalCountsFromAnEstimator) {
  // est 12.5, target 17.5, N 60: 0.3 * 5 / 47.5.
  Broadcast b = ExpectationLaw(17.5, 12.5, 60, 0.3);
  EXPECT_NEAR(b.p_on, 1.5 / 47.5, 1e-15);
  EXPECT_DOUBLE_EQ(b.p_off, 0);
}

TEST(ExpectationLaw, OnTargetBroadcastsNothing) {
  Broadcast b = ExpectationLaw(25, 25, 60, 1.0);
  EXPECT_EQ(b.p_on, 0);
  EXPECT_EQ(b.p_off, 0);
}

TEST(ExpectationLaw, LambdaOneRecruitsAllMissingInOneStep) {
  // lambda = 1: from all off to target 60 -> p_on = 1; from all on to 0 -> p_off = 1.
  EXPECT_DOUBLE_EQ(ExpectationLaw(60, 0, 60, 1.0).p_on, 1.0);
  EXPECT_DOUBLE_EQ(ExpectationLaw(0, 60, 60, 1.0).p_off, 1.0);
  // Half way: 30 on, target 45 -> 15 / 30.
  EXPECT_DOUBLE_EQ(ExpectationLaw(45, 30, 60, 1.0).p_on, 0.5);
}

TEST(ExpectationLaw, NoUnitOffGuard) {
  // All units on (est = N) and the reference asks for more than N: nothing can be recruited,
  // no division by zero.
  Broadcast b = ExpectationLaw(75, 60, 60, 0.5);
  EXPECT_EQ(b.p_on, 0);
  EXPECT_EQ(b.p_off, 0);
  // An estimate above N is clamped to N first: still no recruits, and a lower target releases
  // lambda * (N - target) / N.
  Broadcast r = ExpectationLaw(30, 66, 60, 0.5);
  EXPECT_EQ(r.p_on, 0);
  EXPECT_DOUBLE_EQ(r.p_off, 0.5 * 30 / 60);
}

TEST(ExpectationLaw, NoUnitOnGuard) {
  // All off (est = 0) and a target below zero (negative force reference): nothing to release.
  Broadcast b = ExpectationLaw(-5, 0, 60, 0.5);
  EXPECT_EQ(b.p_on, 0);
  EXPECT_EQ(b.p_off, 0);
  // A negative estimate is clamped to 0: target 6 recruits 0.5 * 6 / 60.
  Broadcast r = ExpectationLaw(6, -3, 60, 0.5);
  EXPECT_DOUBLE_EQ(r.p_on, 0.05);
  EXPECT_EQ(r.p_off, 0);
}

TEST(ExpectationLaw, ClampsToTheUnitInterval) {
  // A lambda above 1 is clamped to 1, so p never exceeds 1.
  Broadcast b = ExpectationLaw(60, 0, 60, 3.0);
  EXPECT_DOUBLE_EQ(b.p_on, 1.0);
  // Target clamped to N: est 59.5, target 1000, lambda 1 -> 0.5 / 0.5 = 1.
  EXPECT_DOUBLE_EQ(ExpectationLaw(1000, 59.5, 60, 1.0).p_on, 1.0);
  // lambda <= 0 does nothing.
  EXPECT_EQ(ExpectationLaw(60, 0, 60, 0.0).p_on, 0);
  EXPECT_EQ(ExpectationLaw(60, 0, 60, -1.0).p_on, 0);
}

TEST(ExpectationLaw, NanOrEmptyBundleBroadcastsNothing) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (Broadcast b : {ExpectationLaw(nan, 10, 60, 0.2), ExpectationLaw(10, nan, 60, 0.2),
                      ExpectationLaw(10, 5, 60, nan), ExpectationLaw(10, 5, 0, 0.2)}) {
    EXPECT_EQ(b.p_on, 0);
    EXPECT_EQ(b.p_off, 0);
  }
}

TEST(ExpectationLaw, ExpectedCountContractsByOneMinusLambda) {
  // With a perfect estimate, E[n_{k+1}] = n_k + p_on (N - n_k) - p_off n_k
  //                                     = n_k + lambda (target - n_k),
  // so the error contracts by (1 - lambda) every step, from above and below.
  for (double lambda : {0.1, 0.2, 0.5, 1.0}) {
    for (double n : {0.0, 13.0, 47.0, 60.0}) {
      const double target = 30;
      Broadcast b = ExpectationLaw(target, n, 60, lambda);
      const double next = n + b.p_on * (60 - n) - b.p_off * n;
      EXPECT_NEAR(next - target, (1 - lambda) * (n - target), 1e-12) << lambda << " " << n;
    }
  }
}

// Exploration keeps the law's expected on count: on (1 - p_off') + off p_on' = on (1 - p_off) +
// off p_on, by hand and over binomial draws (4 standard errors).
TEST(ExplorationLaw, RecruitsAndReleasesAtTheLawsExpectedCount) {
  // 30 on, 20 off, the law idle: p_on 0.3, p_off = 20 x 0.3 / 30 = 0.2.
  Broadcast b = ExplorationLaw({}, 30, 20, 0.3);
  EXPECT_DOUBLE_EQ(b.p_on, 0.3);
  EXPECT_DOUBLE_EQ(b.p_off, 0.2);
  // The law recruits 0.05 of 20 (one unit): p_off = 20 (0.3 - 0.05) / 30.
  b = ExplorationLaw({0.05, 0}, 30, 20, 0.3);
  EXPECT_DOUBLE_EQ(b.p_off, 20 * 0.25 / 30);
  EXPECT_NEAR(30 * (1 - b.p_off) + 20 * b.p_on, 30 + 20 * 0.05, 1e-12);
  // The law releases: the extra release adds to it.
  b = ExplorationLaw({0, 0.1}, 30, 20, 0.3);
  EXPECT_NEAR(30 * (1 - b.p_off) + 20 * b.p_on, 30 * 0.9, 1e-12);
  std::mt19937_64 rng(7);
  std::binomial_distribution<int> up(20, b.p_on), down(30, b.p_off);
  const int draws = 20000;
  double sum = 0, sum2 = 0;
  for (int i = 0; i < draws; ++i) {
    const double on = 30 - down(rng) + up(rng);
    sum += on, sum2 += on * on;
  }
  const double mean = sum / draws, var = sum2 / draws - mean * mean;
  EXPECT_NEAR(mean, 27.0, 4 * std::sqrt(var / draws));
  EXPECT_NEAR(var, 20 * b.p_on * (1 - b.p_on) + 30 * b.p_off * (1 - b.p_off), 0.05 * var);
}

TEST(ExplorationLaw, CapsAndGuards) {
  // 10 on, 50 off, p 0.5: p_off would be 2.5, capped at 1.
  EXPECT_DOUBLE_EQ(ExplorationLaw({}, 10, 50, 0.5).p_off, 1.0);
  // No on unit to release, no off unit, or a law already above p: the law as it is.
  const Broadcast law{0.4, 0};
  for (const Broadcast& b : {ExplorationLaw(law, 0, 60, 0.5), ExplorationLaw(law, 60, 0, 0.5),
                             ExplorationLaw(law, 30, 30, 0.3)}) {
    EXPECT_EQ(b.p_on, law.p_on);
    EXPECT_EQ(b.p_off, law.p_off);
  }
}

}  // namespace file_expectation_law_test
}  // namespace recruit::control
