#include "control/actuator_response.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "common/rng.h"

namespace recruit::control {
namespace file_actuator_response_test {

// With the two-state chain (no thermal lag) the expected on-count closes lambda of its gap each
// period, so the tension's step response is 1 - (1 - lambda)^k exactly.
TEST(ActuatorResponse, TwoStateChainGivesTheExpectationLawsGeometricApproach) {
  const auto chain = estimation::BroadcastTransitionModel::TwoState(0.5);
  for (double lambda : {0.1, 0.2, 0.5, 1.0}) {
    auto r = PredictActuatorResponse(chain, {0.0, 0.45}, lambda);
    ASSERT_TRUE(r.ok()) << r.error();
    EXPECT_DOUBLE_EQ(r->dT, 0.5);
    for (size_t k = 0; k < r->s.size(); ++k) {
      EXPECT_NEAR(r->s[k], 1 - std::pow(1 - lambda, static_cast<double>(k)), 1e-9) << k;
    }
    // Time to 63 %: k = ln(0.37) / ln(1 - lambda) periods (linear between samples).
    if (lambda < 1) {
      const double k = std::log(0.37) / std::log(1 - lambda);
      EXPECT_NEAR(r->TimeTo(0.63), 0.5 * k, 0.5 * 0.1);
    }
  }
}

TEST(ActuatorResponse, AHeatingChainLagsTheCountAndStillSettles) {
  const auto chain = estimation::BroadcastTransitionModel::HeatingChain(20, 1.0);
  std::vector<double> force(20, 0.0);
  for (int i = 1; i <= 10; ++i) force[i] = 0.05 * i;  // rising while heating, settled at 10
  for (int i = 11; i < 20; ++i) force[i] = 0.05 * (20 - i);
  auto r = PredictActuatorResponse(chain, force, 0.2);
  ASSERT_TRUE(r.ok()) << r.error();
  auto two =
      PredictActuatorResponse(estimation::BroadcastTransitionModel::TwoState(1.0), {0, 0.5}, 0.2);
  // Slower than the count alone, and settled by the end.
  EXPECT_GT(r->TimeTo(0.63), two->TimeTo(0.63) + 1.0);
  EXPECT_NEAR(r->s.back(), 1.0, 1e-3);
}

// On the two-state chain (no thermal lag) the law closes lambda of the gap each period either
// way, so the release is the rise: both 1 - (1 - lambda)^k.
TEST(ActuatorResponse, TwoStateChainReleasesAsItRises) {
  const double lambda = 0.3;
  auto r =
      PredictBundleResponse(estimation::BroadcastTransitionModel::TwoState(1.0), {0, 0.5}, lambda);
  ASSERT_TRUE(r.ok()) << r.error();
  ASSERT_GE(r->release.size(), 10u);
  for (size_t k = 0; k < r->release.size(); ++k) {
    EXPECT_NEAR(r->release[k], 1 - std::pow(1 - lambda, static_cast<double>(k)), 1e-9) << k;
  }
}

// A chain whose released units keep pulling while they cool: off, on, and off-but-hot (pulling
// as an on unit does, cooling to off with probability c per period). The law moves the on
// fraction by lambda of its gap either way, so the rise is geometric and the release lags it
// by the hot units. With r = 1 - lambda and q = 1 - c, from the chain by hand:
//   rise     s(k) = 1 - r^k
//   release  s(k) = 1 - r^k - lambda (q^k - r^k) / (q - r)
TEST(ActuatorResponse, UnitsThatPullWhileTheyCoolSlowOnlyTheRelease) {
  const double lambda = 0.2, c = 0.3, r = 1 - lambda, q = 1 - c;
  estimation::BroadcastTransitionModel chain;
  chain.state_names = {"off", "on", "hot"};
  chain.is_on = {false, true, false};
  chain.interior = Eigen::Matrix3d::Identity();
  chain.interior(0, 2) = c;  // a hot unit cools to off
  chain.interior(2, 2) = 1 - c;
  chain.on_target = {1, -1, 1};
  chain.off_target = {-1, 2, -1};
  chain.dt = 0.5;
  ASSERT_TRUE(chain.Validate().ok());
  auto b = PredictBundleResponse(chain, {0, 1, 1}, lambda);
  ASSERT_TRUE(b.ok()) << b.error();
  ASSERT_GE(b->s.size(), 20u);
  ASSERT_GE(b->release.size(), 20u);
  for (size_t k = 0; k < b->s.size(); ++k) {
    EXPECT_NEAR(b->s[k], 1 - std::pow(r, k), 1e-9) << k;
  }
  for (size_t k = 0; k < b->release.size(); ++k) {
    const double want = 1 - std::pow(r, k) - lambda * (std::pow(q, k) - std::pow(r, k)) / (q - r);
    EXPECT_NEAR(b->release[k], want, 1e-9) << k;
  }
  // The release is the slower, and the two views swap the directions.
  EXPECT_GT(b->Released().TimeTo(0.63), b->TimeTo(0.63) + 2 * chain.dt);
  EXPECT_EQ(b->Released().s, b->release);
  EXPECT_TRUE(b->Released().release.empty());
  EXPECT_EQ(b->Reversed().s, b->release);
  EXPECT_EQ(b->Reversed().release, b->s);
  // Without a release of its own a response releases as it rises.
  ActuatorResponse rise = *b;
  rise.release.clear();
  EXPECT_EQ(rise.Released().s, rise.s);
  EXPECT_TRUE(rise.Reversed().release.empty());
}

// At divides by dT with a multiplication when dT is a power of two: the same bits as the
// division for every t (normal, subnormal, zero, negative, huge, infinite) and every dT, a power
// of two or not (including ones whose reciprocal would not be normal).
TEST(ActuatorResponse, QuotientIsTheDivisionBitForBit) {
  auto same = [](double a, double b) {
    std::uint64_t x, y;
    std::memcpy(&x, &a, sizeof x);
    std::memcpy(&y, &b, sizeof y);
    return x == y || (std::isnan(a) && std::isnan(b));
  };
  const double inf = std::numeric_limits<double>::infinity();
  const double tiny = std::numeric_limits<double>::denorm_min();
  const double big = std::numeric_limits<double>::max();
  std::vector<double> divisors = {1,
                                  2,
                                  0.5,
                                  0.25,
                                  4,
                                  1024,
                                  0.3,
                                  0.1,
                                  1.5,
                                  3,
                                  0.75,
                                  std::ldexp(1.0, -1022),
                                  std::ldexp(1.0, -1021),
                                  std::ldexp(1.0, 1022),
                                  std::ldexp(1.0, 1023),
                                  tiny,
                                  big,
                                  -0.5,
                                  -1.0};
  std::vector<double> ts = {0.0,
                            -0.0,
                            1.0,
                            -1.0,
                            0.3,
                            1e-310,
                            -1e-310,
                            tiny,
                            big,
                            -big,
                            inf,
                            -inf,
                            std::nan(""),
                            3.0000000000000004,
                            19.999999999999996};
  Rng rng(7);
  for (int i = 0; i < 20000; ++i) {
    const double u = rng.Uniform();
    ts.push_back(std::ldexp(u, static_cast<int>(rng.Uniform() * 2100) - 1075));
    ts.push_back(-40 * u);
    ts.push_back(60 * u);
  }
  for (double d : divisors) {
    for (double t : ts) {
      ASSERT_TRUE(same(ActuatorResponse::Quotient(t, d), t / d)) << t << " / " << d;
    }
  }
  // And At with it, against the interpolation written with the division.
  ActuatorResponse r;
  r.s = {0, 0.2, 0.5, 0.7, 0.9, 1.0};
  for (double dT : {1.0, 0.5, 2.0, 0.3}) {
    r.dT = dT;
    for (int i = 0; i < 2000; ++i) {
      const double t = 8 * dT * rng.Uniform() - dT;
      const double k = t / dT;
      double want;
      if (k <= 0) {
        want = r.s.front();
      } else if (static_cast<size_t>(k) + 1 >= r.s.size()) {
        want = r.s.back();
      } else {
        const size_t j = static_cast<size_t>(k);
        want = r.s[j] + (k - j) * (r.s[j + 1] - r.s[j]);
      }
      ASSERT_TRUE(same(r.At(t), want)) << t << " at dT " << dT;
    }
  }
}

TEST(ActuatorResponse, BadInputsAreRefused) {
  const auto chain = estimation::BroadcastTransitionModel::TwoState(0.5);
  EXPECT_FALSE(PredictActuatorResponse(chain, {0.0}, 0.2).ok());
  EXPECT_FALSE(PredictActuatorResponse(chain, {0.0, 0.4}, 0).ok());
  EXPECT_FALSE(PredictActuatorResponse(chain, {0.0, 0.0}, 0.2).ok());
}

}  // namespace file_actuator_response_test
}  // namespace recruit::control
