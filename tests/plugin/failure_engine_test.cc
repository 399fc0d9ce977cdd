// Failures in the engine plugin as a stock MuJoCo program sees them: the sensor's working, open
// and stuck counts, and plugin_state exact under mj_copyData and mj_resetData with failures.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tests/plugin/mujoco_util.h"

namespace recruit::sma {
namespace file_failure_engine_test {

using testing::Bench;
using testing::BenchXml;
using testing::ConfigXml;
using testing::DataPtr;
using testing::ModelPtr;
using testing::PluginState;

std::string FailingBench(const std::string& extra) {
  return BenchXml({ConfigXml("units", "40") + ConfigXml("seed", "5") +
                       ConfigXml("broadcast_period", "0.05") + extra,
                   "bundle", "tendon=\"bundle\"", "ctrlrange=\"-1 1\"", "Euler", false});
}

ModelPtr MustLoad(const std::string& xml) {
  auto m = testing::Load(xml);
  EXPECT_TRUE(m.ok()) << m.error();
  return m.ok() ? std::move(m).value() : nullptr;
}

// Steps with a ctrl that alternates recruiting and releasing; returns plugin_state per step.
std::vector<std::vector<double>> Drive(const mjModel* m, mjData* d, int steps) {
  std::vector<std::vector<double>> out;
  for (int i = 0; i < steps; ++i) {
    d->ctrl[0] = (static_cast<int>(d->time / 0.7) % 2 == 0) ? 0.3 : -0.3;
    mj_step(m, d);
    out.push_back(PluginState(m, d));
  }
  return out;
}

TEST(EngineFailures, SensorReportsWorkingOpenAndStuckCounts) {
  ModelPtr plain = MustLoad(FailingBench(""));
  ModelPtr m = MustLoad(FailingBench(ConfigXml("failures", "0.5:4:open,1:2:stuck")));
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(plain->sensor_dim[0], 4);  // no failure key: the layout of before
  EXPECT_EQ(m->sensor_dim[0], 7);
  DataPtr d(mj_makeData(m.get()));
  auto at = [&](int v) { return d->sensordata[m->sensor_adr[0] + v]; };
  mj_forward(m.get(), d.get());
  EXPECT_EQ(at(4), 40);
  while (d->time < 1.2) {
    d->ctrl[0] = 1;
    mj_step(m.get(), d.get());
  }
  mj_forward(m.get(), d.get());
  EXPECT_EQ(at(4), 34);
  EXPECT_EQ(at(5), 4);
  EXPECT_EQ(at(6), 2);
  EXPECT_EQ(at(0), 36);  // every unit but the open ones is heated
  while (d->time < 1.5) {
    d->ctrl[0] = -1;
    mj_step(m.get(), d.get());
  }
  mj_forward(m.get(), d.get());
  EXPECT_EQ(at(0), 2);  // the stuck ones stay on
}

TEST(EngineFailures, CopyAndResetStayExactWithHazardsAndFatigue) {
  ModelPtr m =
      MustLoad(FailingBench(ConfigXml("open_rate", "300") + ConfigXml("stuck_rate", "100") +
                            ConfigXml("open_per_cycle", "0.01") + ConfigXml("fatigue_loss", "0.2") +
                            ConfigXml("fatigue_cycles", "3")));
  ASSERT_NE(m, nullptr);
  DataPtr a(mj_makeData(m.get()));
  const std::vector<double> initial = PluginState(m.get(), a.get());
  const auto first = Drive(m.get(), a.get(), 3000);
  DataPtr b(mj_copyData(nullptr, m.get(), a.get()));
  const auto ca = Drive(m.get(), a.get(), 3000);
  const auto cb = Drive(m.get(), b.get(), 3000);
  for (size_t i = 0; i < ca.size(); ++i) ASSERT_EQ(ca[i], cb[i]) << "step " << i;
  EXPECT_LT(a->sensordata[m->sensor_adr[0] + 4], 40);  // some units failed
  mj_resetData(m.get(), a.get());
  EXPECT_EQ(PluginState(m.get(), a.get()), initial);
  const auto again = Drive(m.get(), a.get(), 3000);
  for (size_t i = 0; i < first.size(); ++i) ASSERT_EQ(first[i], again[i]) << "step " << i;
}

}  // namespace file_failure_engine_test
}  // namespace recruit::sma
