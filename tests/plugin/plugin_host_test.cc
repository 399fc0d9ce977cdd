// The host API (SmaHost, linked library) against what the engine plugin itself reports through
// its sensor, and the fit check of bundles on a model the project did not write.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "common/rng.h"
#include "plugin/sma_host.h"
#include "tests/plugin/mujoco_util.h"

namespace recruit::sma {
namespace {

using ::testing::HasSubstr;
using testing::DataPtr;
using testing::ModelPtr;

// (f) The plugin sensor (count, tension, mean T, mean xi per bundle) equals the host API's
// OnCount, Force, MeanTemperature and MeanXi exactly, on the two-bundle elbow arm while the
// bundles switch at random and the elbow moves.
TEST(PluginSensor, ReportsWhatTheHostApiReads) {
  auto m = LoadModel(RECRUIT_SOURCE_DIR "/models/elbow_arm.xml");
  ASSERT_TRUE(m.ok()) << m.error();
  const mjModel* mm = m->get();
  auto host = SmaHost::Create(mm);
  ASSERT_TRUE(host.ok()) << host.error();
  const SmaHost& h = **host;
  ASSERT_EQ(h.num_bundles(), 2);
  int sensors[2];
  sensors[0] = mj_name2id(mm, mjOBJ_SENSOR, "flexor_truth");
  sensors[1] = mj_name2id(mm, mjOBJ_SENSOR, "extensor_truth");
  ASSERT_GE(sensors[0], 0);
  ASSERT_GE(sensors[1], 0);
  DataPtr d(mj_makeData(mm));
  h.Reset(d.get(), 5);
  Rng rng(99);
  int checks = 0, max_on = 0;
  const int flexor = h.BundleIndex("flexor"), extensor = h.BundleIndex("extensor");
  ASSERT_EQ(mm->sensor_dim[sensors[0]], 4);
  for (int step = 0; step < 3000; ++step) {
    if (step % 50 == 0) {
      ASSERT_TRUE(h.Broadcast(d.get(), flexor, 0.3 * rng.Uniform(), 0.2 * rng.Uniform()).ok());
      ASSERT_TRUE(h.Broadcast(d.get(), extensor, 0.1 * rng.Uniform(), 0.3 * rng.Uniform()).ok());
    }
    mj_step(mm, d.get());
    if (step % 97 != 0) continue;
    mj_forward(mm, d.get());
    for (int s = 0; s < 2; ++s) {
      const int b = s == 0 ? flexor : extensor;
      const double* v = d->sensordata + mm->sensor_adr[sensors[s]];
      EXPECT_EQ(v[0], h.OnCount(d.get(), b));
      EXPECT_EQ(v[1], h.Force(d.get(), b));
      EXPECT_EQ(v[2], h.MeanTemperature(d.get(), b));
      EXPECT_EQ(v[3], h.MeanXi(d.get(), b));
      // and the actuator force is minus the tension
      EXPECT_EQ(d->actuator_force[h.actuator_id(b)], -v[1]);
      max_on = std::max(max_on, h.OnCount(d.get(), b));
      ++checks;
    }
  }
  EXPECT_GT(checks, 50);
  EXPECT_GT(max_on, 0);
}

}  // namespace
}  // namespace recruit::sma
