// plugin_state holds only finite numbers (issue 25 item 7): the whole physics state that
// mj_getState returns passes a NaN check at every step of varied runs, and the state written as
// text (%.17g) and read back continues the run bit for bit.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "common/rng.h"
#include "tests/plugin/mujoco_util.h"

namespace recruit::sma {
namespace file_plugin_state_test {

using testing::DataPtr;
using testing::Load;
using testing::ModelPtr;
using testing::SameBits;

// Three bundles on two instances: one every-step, one with update_period > 0 and a broadcast
// period, on a slide joint that moves so the extensions change.
std::string ThreeBundles() {
  return R"(<mujoco>
  <compiler autolimits="true"/>
  <option timestep="0.002"/>
  <extension><plugin plugin="recruit.sma">
    <instance name="a"><config key="units" value="30"/><config key="seed" value="5"/></instance>
    <instance name="b"><config key="units" value="25"/><config key="update_period" value="0.01"/>
      <config key="broadcast_period" value="0.02"/><config key="seed" value="9"/></instance>
  </plugin></extension>
  <worldbody>
    <site name="s0" pos="0 0 0"/>
    <body name="slider" pos="0.1 0 0">
      <joint name="x" type="slide" axis="1 0 0" stiffness="200" damping="5" range="-0.01 0.01"/>
      <geom type="box" size="0.01 0.01 0.01" mass="0.1"/>
      <site name="s1"/>
    </body>
    <site name="s2" pos="-0.1 0 0"/>
  </worldbody>
  <tendon>
    <spatial name="t1"><site site="s0"/><site site="s1"/></spatial>
    <spatial name="t2"><site site="s2"/><site site="s1"/></spatial>
  </tendon>
  <actuator>
    <plugin name="p1" instance="a" tendon="t1" ctrlrange="-1 1"/>
    <plugin name="p2" instance="a" tendon="t2" ctrlrange="-1 1"/>
    <plugin name="p3" instance="b" tendon="t2" ctrlrange="-1 1"/>
  </actuator>
  <sensor><plugin name="ta" instance="a"/><plugin name="tb" instance="b"/></sensor>
</mujoco>)";
}

// Random signed broadcasts that depend only on the step number (so a restored run gets the
// same controls).
void SetControls(const mjModel* m, mjData* d, int step) {
  Rng rng(Rng::DeriveSeed(17, step));
  for (int a = 0; a < m->nu; ++a) {
    const double u = rng.Uniform();
    d->ctrl[a] = u < 0.4 ? 0.0 : 2 * rng.Uniform() - 1;
  }
}

std::vector<double> FullState(const mjModel* m, const mjData* d) {
  std::vector<double> s(mj_stateSize(m, mjSTATE_FULLPHYSICS));
  mj_getState(m, d, s.data(), mjSTATE_FULLPHYSICS);
  return s;
}

TEST(PluginStateIsFinite, AtEveryStepOfRandomBroadcastRuns) {
  testing::WarningCapture fit;  // the slide moves the tendons past the units' stroke: not the point
  auto loaded = Load(ThreeBundles());
  ASSERT_TRUE(loaded.ok()) << loaded.error();
  const mjModel* m = loaded->get();
  ASSERT_GT(m->npluginstate, 0);
  for (int run = 0; run < 3; ++run) {
    DataPtr d(mj_makeData(m));
    ASSERT_NE(d, nullptr);
    for (int step = 0; step < 1500; ++step) {
      SetControls(m, d.get(), 1000 * run + step);
      mj_step(m, d.get());
      const std::vector<double> s = FullState(m, d.get());
      for (size_t i = 0; i < s.size(); ++i) {
        ASSERT_TRUE(std::isfinite(s[i])) << "run " << run << " step " << step << " index " << i;
      }
    }
    // The run switched units (else the stream never moved and the test shows little).
    mj_forward(m, d.get());
    EXPECT_GT(d->sensordata[0] + d->sensordata[4] + d->sensordata[8], 0);
  }
}

TEST(PluginStateIsFinite, TextRoundTripOfTheStateContinuesBitForBit) {
  testing::WarningCapture fit;
  auto loaded = Load(ThreeBundles());
  ASSERT_TRUE(loaded.ok()) << loaded.error();
  const mjModel* m = loaded->get();
  DataPtr d(mj_makeData(m));
  int step = 0;
  for (; step < 700; ++step) {
    SetControls(m, d.get(), step);
    mj_step(m, d.get());
  }
  // Write the state as text and read it back into a fresh mjData.
  std::string text;
  for (double v : FullState(m, d.get())) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g ", v);
    text += buf;
  }
  std::vector<double> parsed;
  std::istringstream in(text);
  for (std::string tok; in >> tok;) parsed.push_back(std::strtod(tok.c_str(), nullptr));
  ASSERT_EQ(parsed.size(), FullState(m, d.get()).size());
  DataPtr copy(mj_makeData(m));
  mj_setState(m, copy.get(), parsed.data(), mjSTATE_FULLPHYSICS);
  ASSERT_TRUE(SameBits(d->plugin_state, copy->plugin_state, m->npluginstate));
  for (int k = 0; k < 800; ++k, ++step) {
    SetControls(m, d.get(), step);
    SetControls(m, copy.get(), step);
    mj_step(m, d.get());
    mj_step(m, copy.get());
  }
  EXPECT_TRUE(SameBits(d->plugin_state, copy->plugin_state, m->npluginstate));
  EXPECT_TRUE(SameBits(d->qpos, copy->qpos, m->nq));
  EXPECT_TRUE(SameBits(d->actuator_force, copy->actuator_force, m->nu));
}

}  // namespace file_plugin_state_test
}  // namespace recruit::sma
