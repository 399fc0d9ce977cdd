#include "control/actuator_response.h"

#include <gtest/gtest.h>

#include <cmath>

namespace recruit::control {
namespace {

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

TEST(ActuatorResponse, BadInputsAreRefused) {
  const auto chain = estimation::BroadcastTransitionModel::TwoState(0.5);
  EXPECT_FALSE(PredictActuatorResponse(chain, {0.0}, 0.2).ok());
  EXPECT_FALSE(PredictActuatorResponse(chain, {0.0, 0.4}, 0).ok());
  EXPECT_FALSE(PredictActuatorResponse(chain, {0.0, 0.0}, 0.2).ok());
}

}  // namespace
}  // namespace recruit::control
