// Unit physics without MuJoCo.
#include "plugin/unit_model.h"

#include <gtest/gtest.h>

#include <cmath>

namespace recruit::sma {
namespace {

TEST(UnitThermal, StepMatchesClosedForm) {
  auto m = UnitModel::Create(UnitParams{});
  ASSERT_TRUE(m.ok()) << m.error();
  const double tau = m->heat_capacity() / m->conductance();
  const double t_ss = 20 + m->HeatingPower(true, 1.0) / m->conductance();
  double t = 20;
  for (int i = 0; i < 1000; ++i) t = m->ThermalStep(t, true, 1.0, 1e-3);
  EXPECT_NEAR(t, t_ss + (20 - t_ss) * std::exp(-1.0 / tau), 1e-9);
}

}  // namespace
}  // namespace recruit::sma
