// The host API on models/isometric_bench.xml: load, reset, broadcast, step, read ground truth.
#include <gtest/gtest.h>

#include <string>

#include "plugin/sma_plugin.h"

namespace recruit::sma {
namespace {

struct Loaded {
  mjModel* m = nullptr;
  std::string error;
  ~Loaded() {
    if (m) mj_deleteModel(m);
  }
};

void LoadFile(const std::string& path, Loaded& out) {
  char err[1000] = "";
  out.m = mj_loadXML(path.c_str(), nullptr, err, sizeof err);
  out.error = err;
}

TEST(HostApi, IsometricBenchLoadsWithOneBundleOfSixtyUnits) {
  Loaded l;
  LoadFile(RECRUIT_SOURCE_DIR "/models/isometric_bench.xml", l);
  ASSERT_NE(l.m, nullptr) << l.error;
  auto p = SmaPlugin::Create(l.m);
  ASSERT_TRUE(p.ok()) << p.error();
  EXPECT_EQ((*p)->num_bundles(), 1);
  EXPECT_EQ((*p)->BundleIndex("bundle"), 0);
  EXPECT_EQ((*p)->BundleIndex("nope"), -1);
  EXPECT_EQ((*p)->num_units(0), 60);
  EXPECT_EQ((*p)->tendon_id(0), mj_name2id(l.m, mjOBJ_TENDON, "bundle"));
  EXPECT_EQ((*p)->actuator_id(0), mj_name2id(l.m, mjOBJ_ACTUATOR, "bundle"));
  auto need = SmaPlugin::RequiredUserdata(l.m);
  ASSERT_TRUE(need.ok());
  EXPECT_EQ(*need, 8 + 8 * 60);
}

TEST(HostApi, AllOnThenTensionRisesAndCountIsExact) {
  Loaded l;
  LoadFile(RECRUIT_SOURCE_DIR "/models/isometric_bench.xml", l);
  ASSERT_NE(l.m, nullptr) << l.error;
  auto p = SmaPlugin::Create(l.m);
  ASSERT_TRUE(p.ok()) << p.error();
  const SmaPlugin& plugin = **p;
  mjData* d = mj_makeData(l.m);
  plugin.Reset(d, 7);
  EXPECT_EQ(plugin.OnCount(d, 0), 0);
  EXPECT_DOUBLE_EQ(plugin.MeanTemperature(d, 0), 20.0);
  EXPECT_DOUBLE_EQ(plugin.Heat(d, 0), 0.0);
  ASSERT_TRUE(plugin.Broadcast(d, 0, 1.0, 0.0).ok());
  EXPECT_EQ(plugin.OnCount(d, 0), 60);
  for (int i = 0; i < 3000; ++i) Step(l.m, d, plugin);
  EXPECT_GT(plugin.Force(d, 0), 10.0);
  EXPECT_GT(plugin.Heat(d, 0), 0.5);
  // The actuator pulls: its force is minus the tension.
  EXPECT_LT(d->actuator_force[0], -10.0);
  EXPECT_GT(plugin.SettledUnitForce(0), 0.3);
  mj_deleteData(d);
}

}  // namespace
}  // namespace recruit::sma
