// The MuJoCo binding: host API, MJCF validation, copy/reset semantics, integrators, several
// models and threads. Inline XML where a test varies the model.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <thread>
#include <vector>

#include "common/rng.h"
#include "plugin/sma_plugin.h"
#include "tests/plugin/mujoco_util.h"

namespace recruit::sma {
namespace {

using testing::BenchXml;
using testing::DataPtr;
using ::testing::HasSubstr;
using testing::LoadXmlFile;
using testing::LoadXmlString;
using testing::MakeData;
using testing::ModelPtr;

constexpr double kPi = 3.14159265358979323846;

std::unique_ptr<SmaPlugin> MustCreate(const mjModel* m) {
  auto p = SmaPlugin::Create(m);
  EXPECT_TRUE(p.ok()) << p.error();
  return p.ok() ? std::move(p.value()) : nullptr;
}

ModelPtr MustLoad(const std::string& xml) {
  std::string err;
  ModelPtr m = LoadXmlString(xml, &err);
  EXPECT_NE(m, nullptr) << err;
  return m;
}

TEST(HostApi, IsometricBenchLoadsWithOneBundleOfSixtyUnits) {
  std::string err;
  ModelPtr m = LoadXmlFile(RECRUIT_SOURCE_DIR "/models/isometric_bench.xml", &err);
  ASSERT_NE(m, nullptr) << err;
  auto p = MustCreate(m.get());
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->num_bundles(), 1);
  EXPECT_EQ(p->BundleIndex("bundle"), 0);
  EXPECT_EQ(p->BundleIndex("nope"), -1);
  EXPECT_EQ(p->bundle_name(0), "bundle");
  EXPECT_EQ(p->num_units(0), 60);
  EXPECT_EQ(p->tendon_id(0), mj_name2id(m.get(), mjOBJ_TENDON, "bundle"));
  EXPECT_EQ(p->actuator_id(0), mj_name2id(m.get(), mjOBJ_ACTUATOR, "bundle"));
  auto need = SmaPlugin::RequiredUserdata(m.get());
  ASSERT_TRUE(need.ok()) << need.error();
  EXPECT_EQ(*need, 8 + 8 * 60);
}

TEST(HostApi, ResetBroadcastStepAndGroundTruth) {
  ModelPtr m = MustLoad(BenchXml());
  auto p = MustCreate(m.get());
  DataPtr d = MakeData(m.get());
  p->Reset(d.get(), 7);
  EXPECT_EQ(p->OnCount(d.get(), 0), 0);
  EXPECT_DOUBLE_EQ(p->MeanTemperature(d.get(), 0), 20.0);
  EXPECT_DOUBLE_EQ(p->Heat(d.get(), 0), 0.0);
  EXPECT_DOUBLE_EQ(p->Force(d.get(), 0), 0.0);
  EXPECT_EQ(p->NumCohorts(d.get(), 0), 1);
  ASSERT_TRUE(p->Broadcast(d.get(), 0, 0.5, 0.0).ok());
  const int on = p->OnCount(d.get(), 0);
  EXPECT_GT(on, 10);
  EXPECT_LT(on, 50);
  EXPECT_DOUBLE_EQ(d->act[0], on / 60.0);  // act mirrors the on fraction
  int on_units = 0;
  for (int i = 0; i < 60; ++i) on_units += p->UnitOn(d.get(), 0, i);
  EXPECT_EQ(on_units, on);
  for (int i = 0; i < 3000; ++i) Step(m.get(), d.get(), *p);
  EXPECT_GT(p->Force(d.get(), 0), 5.0);
  EXPECT_GT(p->Heat(d.get(), 0), 0.2);
  for (int i = 0; i < 60; ++i) {
    EXPECT_EQ(p->UnitTemperature(d.get(), 0, i) > 100, p->UnitOn(d.get(), 0, i)) << i;
    EXPECT_EQ(p->UnitXi(d.get(), 0, i) < 0.9, p->UnitOn(d.get(), 0, i)) << i;
  }
  // The actuator pulls: its force is minus the tension.
  EXPECT_NEAR(d->actuator_force[0], -p->Force(d.get(), 0), 0.05);
  EXPECT_GT(p->SettledUnitForce(0), 0.3);
  EXPECT_LT(p->SettledUnitForce(0), 0.6);
}

// The paper's Fig. 4 (PAPER.md sec. 5): 60 units at constant length switched off -> on reach
// about 25-30 N, about 75 % of it in about 2 s, settle in about 5 s.
struct StepFigures {
  double peak = 0, t75 = -1, settle = 0, relax = -1;
};

StepFigures RunFigure4(const mjModel* m, const SmaPlugin& p) {
  DataPtr d = MakeData(m);
  p.Reset(d.get(), 1);
  (void)p.Broadcast(d.get(), 0, 1, 0);
  std::vector<double> t, f;
  const int on_steps = 10000, off_steps = 6000;
  for (int i = 0; i < on_steps + off_steps; ++i) {
    if (i == on_steps) (void)p.Broadcast(d.get(), 0, 0, 1);
    Step(m, d.get(), p);
    t.push_back((i + 1) * m->opt.timestep);
    f.push_back(p.Force(d.get(), 0));
  }
  StepFigures s;
  s.peak = f[on_steps - 1];
  for (int i = 0; i < on_steps; ++i) {
    if (s.t75 < 0 && f[i] >= 0.75 * s.peak) s.t75 = t[i];
    if (std::abs(f[i] - s.peak) > 0.05 * s.peak) s.settle = t[i];
  }
  for (int i = on_steps; i < on_steps + off_steps; ++i) {
    if (s.relax < 0 && f[i] <= 0.05 * s.peak) s.relax = t[i] - t[on_steps - 1];
  }
  return s;
}

TEST(IsometricBench, StepResponseMatchesPaperFigure4) {
  std::string err;
  ModelPtr m = LoadXmlFile(RECRUIT_SOURCE_DIR "/models/isometric_bench.xml", &err);
  ASSERT_NE(m, nullptr) << err;
  auto p = MustCreate(m.get());
  const StepFigures s = RunFigure4(m.get(), *p);
  EXPECT_GE(s.peak, 25.0);
  EXPECT_LE(s.peak, 30.0);
  EXPECT_GE(s.t75, 1.5);
  EXPECT_LE(s.t75, 2.5);
  EXPECT_GE(s.settle, 3.5);  // last time outside +-5 % of the 10 s force
  EXPECT_LE(s.settle, 6.0);
  EXPECT_GT(s.relax, 0.5);  // back under 5 % "within a few seconds"
  EXPECT_LE(s.relax, 3.0);
}

TEST(IsometricBench, CoarserUnitUpdatePeriodKeepsTheForceWithinOnePercent) {
  // update_period=0.01: units integrated every 10 steps (exact thermal step, implicit phase).
  ModelPtr me = MustLoad(BenchXml("units=60"));
  ModelPtr mc = MustLoad(BenchXml("units=60 update_period=0.01"));
  auto pe = MustCreate(me.get());
  auto pc = MustCreate(mc.get());
  DataPtr de = MakeData(me.get()), dc = MakeData(mc.get());
  pe->Reset(de.get(), 8);
  pc->Reset(dc.get(), 8);
  double max_diff = 0, max_force = 0;
  for (int i = 0; i < 12000; ++i) {
    if (i % 1500 == 0) {  // broadcasts between unit updates flush the pending time first
      ASSERT_TRUE(pe->Broadcast(de.get(), 0, 0.5, 0.3).ok());
      ASSERT_TRUE(pc->Broadcast(dc.get(), 0, 0.5, 0.3).ok());
    }
    Step(me.get(), de.get(), *pe);
    Step(mc.get(), dc.get(), *pc);
    ASSERT_EQ(pe->OnCount(de.get(), 0), pc->OnCount(dc.get(), 0));
    max_diff = std::max(max_diff, std::abs(pe->Force(de.get(), 0) - pc->Force(dc.get(), 0)));
    max_force = std::max(max_force, pe->Force(de.get(), 0));
  }
  EXPECT_GT(max_force, 10.0);
  EXPECT_LT(max_diff, 0.01 * max_force) << max_diff << " N of " << max_force << " N";
  std::printf("[ info ] update_period=0.01: max |dF| = %.3g N of %.3g N\n", max_diff, max_force);
}

TEST(IsometricBench, ForceFollowsTendonLengthWithSpringStiffness) {
  ModelPtr m = MustLoad(BenchXml());
  auto p = MustCreate(m.get());
  DataPtr d = MakeData(m.get());
  p->Reset(d.get(), 1);
  ASSERT_TRUE(p->Broadcast(d.get(), 0, 1, 0).ok());
  for (int i = 0; i < 1500; ++i) Step(m.get(), d.get(), *p);  // mid-transformation
  const double xi = p->UnitXi(d.get(), 0, 0);
  ASSERT_GT(xi, 0.05);
  ASSERT_LT(xi, 0.95);
  // Spring formulas with the defaults (plugin/README.md): d = 0.1 mm, D = 0.33 mm, n = 20.
  const double wd = 0.1e-3, cd = 0.33e-3, n = 20, eps_l = 0.04;
  const double geom = std::pow(wd, 4) / (8 * cd * cd * cd * n);
  const double k = (28e9 + xi * (10.5e9 - 28e9)) * geom;
  const double stretch_l = kPi * n * cd * cd * std::sqrt(3.0) * eps_l / wd;
  for (double dx : {-2e-3, -1e-3, 0.0, 0.5e-3, 1e-3}) {
    d->qpos[0] = dx;  // the load cell moves along +x: the tendon lengthens by dx
    mj_forward(m.get(), d.get());
    const double stretch = 3e-3 + (d->ten_length[0] - m->tendon_length0[0]);
    const double expected = 60 * std::max(0.0, k * (stretch - xi * stretch_l));
    EXPECT_NEAR(p->Force(d.get(), 0), expected, 1e-9) << "dx=" << dx;
    EXPECT_NEAR(d->actuator_force[0], -expected, 1e-9) << "dx=" << dx;
  }
}

TEST(HostApi, CopyDataForksAnIdenticalTrajectory) {
  ModelPtr m = MustLoad(BenchXml());
  auto p = MustCreate(m.get());
  DataPtr a = MakeData(m.get());
  p->Reset(a.get(), 99);
  Rng control(5);
  auto run = [&](mjData* d, int steps, Rng& c) {
    std::vector<double> f;
    for (int i = 0; i < steps; ++i) {
      if (i % 200 == 0) {
        const double on = 0.3 * c.Uniform(), off = 0.3 * c.Uniform();
        EXPECT_TRUE(p->Broadcast(d, 0, on, off).ok());
      }
      Step(m.get(), d, *p);
      f.push_back(p->Force(d, 0));
    }
    return f;
  };
  run(a.get(), 2000, control);
  DataPtr b = MakeData(m.get());
  mj_copyData(b.get(), m.get(), a.get());
  Rng control_b = control;
  const auto fa = run(a.get(), 3000, control);
  const auto fb = run(b.get(), 3000, control_b);
  EXPECT_EQ(fa, fb);
  for (int i = 0; i < m->nuserdata; ++i) ASSERT_EQ(a->userdata[i], b->userdata[i]) << i;
  EXPECT_EQ(a->qpos[0], b->qpos[0]);
}

TEST(HostApi, CallbacksArePureSoRepeatedForwardChangesNothing) {
  ModelPtr m = MustLoad(BenchXml());
  auto p = MustCreate(m.get());
  DataPtr d = MakeData(m.get());
  p->Reset(d.get(), 3);
  ASSERT_TRUE(p->Broadcast(d.get(), 0, 0.5, 0).ok());
  for (int i = 0; i < 1000; ++i) Step(m.get(), d.get(), *p);
  const std::vector<double> before(d->userdata, d->userdata + m->nuserdata);
  mj_forward(m.get(), d.get());
  const double f1 = d->actuator_force[0];
  for (int k = 0; k < 5; ++k) mj_forward(m.get(), d.get());
  EXPECT_EQ(std::vector<double>(d->userdata, d->userdata + m->nuserdata), before);
  EXPECT_EQ(d->actuator_force[0], f1);
}

TEST(HostApi, EulerAndRk4AgreeWithinOneHundredthPercent) {
  ModelPtr me = MustLoad(BenchXml("units=60", 488, "", "Euler"));
  ModelPtr mr = MustLoad(BenchXml("units=60", 488, "", "RK4"));
  auto pe = MustCreate(me.get());
  auto pr = MustCreate(mr.get());
  DataPtr de = MakeData(me.get()), dr = MakeData(mr.get());
  pe->Reset(de.get(), 4);
  pr->Reset(dr.get(), 4);
  double max_diff = 0, max_force = 0;
  for (int i = 0; i < 8000; ++i) {
    if (i % 1000 == 0) {
      ASSERT_TRUE(pe->Broadcast(de.get(), 0, 0.4, 0.2).ok());
      ASSERT_TRUE(pr->Broadcast(dr.get(), 0, 0.4, 0.2).ok());
    }
    Step(me.get(), de.get(), *pe);
    Step(mr.get(), dr.get(), *pr);
    ASSERT_EQ(pe->OnCount(de.get(), 0), pr->OnCount(dr.get(), 0));
    max_diff = std::max(max_diff, std::abs(pe->Force(de.get(), 0) - pr->Force(dr.get(), 0)));
    max_force = std::max(max_force, pe->Force(de.get(), 0));
  }
  EXPECT_GT(max_force, 10.0);
  EXPECT_LT(max_diff, 1e-4 * max_force) << "max |F_euler - F_rk4| = " << max_diff << " N";
  std::printf("[ info ] max |F_euler - F_rk4| = %.3g N of %.3g N\n", max_diff, max_force);
}

TEST(HostApi, ResetKeyframeRestoresPoseAndColdUnits) {
  ModelPtr m = MustLoad(BenchXml());
  auto p = MustCreate(m.get());
  DataPtr d = MakeData(m.get());
  p->Reset(d.get(), 1);
  ASSERT_TRUE(p->Broadcast(d.get(), 0, 1, 0).ok());
  for (int i = 0; i < 2000; ++i) Step(m.get(), d.get(), *p);
  ASSERT_GT(p->MeanTemperature(d.get(), 0), 60);
  EXPECT_FALSE(p->ResetKeyframe(d.get(), 1, 1).ok());  // the model has one keyframe
  ASSERT_TRUE(p->ResetKeyframe(d.get(), 0, 1).ok());
  EXPECT_EQ(d->qpos[0], 0.0005);
  EXPECT_EQ(d->time, 0.0);
  EXPECT_EQ(p->OnCount(d.get(), 0), 0);
  EXPECT_EQ(d->act[0], 0.0);
  EXPECT_DOUBLE_EQ(p->MeanTemperature(d.get(), 0), 20.0);
  EXPECT_EQ(p->UnitXi(d.get(), 0, 0), 1.0);
  // Same seed after the same reset: the same draws as a fresh run.
  DataPtr fresh = MakeData(m.get());
  ASSERT_TRUE(p->ResetKeyframe(fresh.get(), 0, 1).ok());
  ASSERT_TRUE(p->Broadcast(d.get(), 0, 0.5, 0).ok());
  ASSERT_TRUE(p->Broadcast(fresh.get(), 0, 0.5, 0).ok());
  for (int i = 0; i < 60; ++i) {
    EXPECT_EQ(p->UnitOn(d.get(), 0, i), p->UnitOn(fresh.get(), 0, i));
  }
}

TEST(HostApi, ZeroedUserdataIsTreatedAsResetWithSeedZero) {
  ModelPtr m = MustLoad(BenchXml());
  auto p = MustCreate(m.get());
  DataPtr a = MakeData(m.get()), b = MakeData(m.get());
  p->Reset(a.get(), 0);
  mj_resetData(m.get(), b.get());  // userdata all zero: callbacks see no units
  mj_forward(m.get(), b.get());
  EXPECT_EQ(b->actuator_force[0], 0.0);
  EXPECT_EQ(p->OnCount(b.get(), 0), 0);
  ASSERT_TRUE(p->Broadcast(a.get(), 0, 0.5, 0).ok());
  ASSERT_TRUE(p->Broadcast(b.get(), 0, 0.5, 0).ok());
  for (int i = 0; i < 60; ++i) EXPECT_EQ(p->UnitOn(a.get(), 0, i), p->UnitOn(b.get(), 0, i));
}

struct BadModel {
  const char* name;
  std::string xml;
  const char* expected;
};

class InvalidModel : public ::testing::TestWithParam<BadModel> {};

TEST_P(InvalidModel, IsRejectedWithMessageNamingTheField) {
  std::string err;
  ModelPtr m = LoadXmlString(GetParam().xml, &err);
  ASSERT_NE(m, nullptr) << err;
  auto p = SmaPlugin::Create(m.get());
  ASSERT_FALSE(p.ok());
  EXPECT_THAT(p.error(), HasSubstr(GetParam().expected));
  // The model stays usable: stepping it without a plugin applies no SMA force.
  DataPtr d = MakeData(m.get());
  mj_step(m.get(), d.get());
  if (m->nu > 0) {
    EXPECT_EQ(d->actuator_force[0], 0.0);
  }
}

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

const std::string kGeneral =
    R"(<general name="bundle" tendon="bundle" dyntype="user" gaintype="user" biastype="user" )";

INSTANTIATE_TEST_SUITE_P(
    AllChecks, InvalidModel,
    ::testing::Values(
        BadModel{"TooLittleUserdata", BenchXml("units=60", 100),
                 "need <size nuserdata=\"488\"/> or more (it has nuserdata=100)"},
        BadModel{"UnknownKey", BenchXml("units=60 curent=1"),
                 "actuator 'bundle' (<custom><text name=\"recruit.sma.bundle\">): unknown key "
                 "'curent'"},
        BadModel{"NegativeCurrent", BenchXml("current=-0.1"),
                 "actuator 'bundle' (<custom><text name=\"recruit.sma.bundle\">): current=-0.1 "
                 "is out of range"},
        BadModel{
            "DyntypeNotUser",
            Replace(
                BenchXml(), kGeneral,
                R"(<general name="bundle" tendon="bundle" dyntype="filter" gaintype="user" biastype="user" )"),
            "actuator 'bundle': dyntype must be \"user\" (is \"filter\")"},
        BadModel{
            "GaintypeNotUser",
            Replace(
                BenchXml(), kGeneral,
                R"(<general name="bundle" tendon="bundle" dyntype="user" gaintype="fixed" biastype="user" )"),
            "actuator 'bundle': gaintype must be \"user\" (is \"fixed\")"},
        BadModel{
            "BiastypeNotUser",
            Replace(
                BenchXml(), kGeneral,
                R"(<general name="bundle" tendon="bundle" dyntype="user" gaintype="user" biastype="none" )"),
            "actuator 'bundle': biastype must be \"user\" (is \"none\")"},
        BadModel{
            "JointTransmission",
            Replace(
                BenchXml(), kGeneral,
                R"(<general name="bundle" joint="load_cell" dyntype="user" gaintype="user" biastype="user" )"),
            "actuator 'bundle': must act on a tendon"},
        BadModel{"GearNotOne", BenchXml("units=60", 488, "gear=\"2\""),
                 "actuator 'bundle': gear must be 1"},
        BadModel{"TextWithoutActuator",
                 Replace(BenchXml(), "recruit.sma.bundle", "recruit.sma.bicep"),
                 "<custom><text name=\"recruit.sma.bicep\">: the model has no actuator named "
                 "'bicep' (actuators: bundle)"},
        BadModel{"NoBundle", Replace(BenchXml(), "recruit.sma.bundle", "other.text"),
                 "model has no SMA bundle"}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(Registry, UnregisteredModelGetsNoForceEvenWhileLoading) {
  ModelPtr a = MustLoad(BenchXml());
  auto p = MustCreate(a.get());  // callbacks are installed from here on
  // Loading runs a test step with the callbacks on a model no plugin knows: it must load.
  ModelPtr b = MustLoad(BenchXml());
  DataPtr d = MakeData(b.get());
  std::fill(d->userdata, d->userdata + b->nuserdata, 1.0);  // garbage the callbacks must ignore
  mj_forward(b.get(), d.get());
  EXPECT_EQ(d->actuator_force[0], 0.0);
}

TEST(Registry, DestroyingThePluginUnregistersItsModel) {
  ModelPtr m = MustLoad(BenchXml());
  DataPtr d = MakeData(m.get());
  {
    auto p = MustCreate(m.get());
    p->Reset(d.get(), 1);
    ASSERT_TRUE(p->Broadcast(d.get(), 0, 1, 0).ok());
    for (int i = 0; i < 2000; ++i) Step(m.get(), d.get(), *p);
    mj_forward(m.get(), d.get());
    ASSERT_LT(d->actuator_force[0], -1.0);
  }
  mj_forward(m.get(), d.get());
  EXPECT_EQ(d->actuator_force[0], 0.0);
}

TEST(Registry, TwoModelsInOneProcessDoNotInterfere) {
  ModelPtr ma = MustLoad(BenchXml("units=60"));
  ModelPtr mb = MustLoad(BenchXml("units=60 current=0.2"));
  auto pa = MustCreate(ma.get());
  auto pb = MustCreate(mb.get());
  auto run = [](const mjModel* m, const SmaPlugin& p, mjData* d, int steps) {
    for (int i = 0; i < steps; ++i) Step(m, d, p);
    return p.Force(d, 0);
  };
  DataPtr a1 = MakeData(ma.get()), b1 = MakeData(mb.get());
  pa->Reset(a1.get(), 1);
  pb->Reset(b1.get(), 1);
  ASSERT_TRUE(pa->Broadcast(a1.get(), 0, 1, 0).ok());
  ASSERT_TRUE(pb->Broadcast(b1.get(), 0, 1, 0).ok());
  double fa = 0, fb = 0;
  for (int k = 0; k < 10; ++k) {  // interleaved
    fa = run(ma.get(), *pa, a1.get(), 300);
    fb = run(mb.get(), *pb, b1.get(), 300);
  }
  DataPtr a2 = MakeData(ma.get()), b2 = MakeData(mb.get());
  pa->Reset(a2.get(), 1);
  pb->Reset(b2.get(), 1);
  ASSERT_TRUE(pa->Broadcast(a2.get(), 0, 1, 0).ok());
  ASSERT_TRUE(pb->Broadcast(b2.get(), 0, 1, 0).ok());
  EXPECT_EQ(run(ma.get(), *pa, a2.get(), 3000), fa);
  EXPECT_EQ(run(mb.get(), *pb, b2.get(), 3000), fb);
  EXPECT_GT(fa, fb + 1.0);  // the lower current pulls less
}

TEST(Registry, ParallelRunsMatchSerialRunsBitForBit) {
  ModelPtr m = MustLoad(BenchXml());
  auto p = MustCreate(m.get());
  auto run = [&](std::uint64_t seed) {
    DataPtr d = MakeData(m.get());
    p->Reset(d.get(), seed);
    std::vector<double> f;
    for (int i = 0; i < 4000; ++i) {
      if (i % 250 == 0) {
        EXPECT_TRUE(p->Broadcast(d.get(), 0, 0.3, 0.3).ok());
      }
      Step(m.get(), d.get(), *p);
      f.push_back(p->Force(d.get(), 0));
    }
    return f;
  };
  std::vector<std::vector<double>> serial(4), parallel(4);
  for (int k = 0; k < 4; ++k) serial[k] = run(k + 1);
  std::vector<std::thread> threads;
  for (int t = 0; t < 2; ++t) {
    threads.emplace_back([&, t] {
      for (int k = t; k < 4; k += 2) parallel[k] = run(k + 1);
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(serial, parallel);
  EXPECT_NE(serial[0], serial[1]);
}

TEST(HostApi, AgonistAndAntagonistBundlesAreIndependent) {
  const std::string xml = R"(<mujoco>
  <compiler autolimits="true"/>
  <option timestep="0.001"/>
  <size nuserdata="600"/>
  <custom>
    <text name="recruit.sma.flexor" data="units=30"/>
    <text name="recruit.sma.extensor" data="units=40 current=0.25"/>
  </custom>
  <worldbody>
    <site name="a" pos="-0.1 0 0"/>
    <site name="b" pos="0.1 0 0"/>
    <body name="slider">
      <joint name="x" type="slide" axis="1 0 0" damping="50"/>
      <geom type="sphere" size="0.01" mass="0.1"/>
      <site name="s"/>
    </body>
  </worldbody>
  <tendon>
    <spatial name="left"><site site="a"/><site site="s"/></spatial>
    <spatial name="right"><site site="s"/><site site="b"/></spatial>
  </tendon>
  <actuator>
    <motor name="push" joint="x"/>
    <general name="flexor" tendon="left" dyntype="user" gaintype="user" biastype="user"/>
    <general name="extensor" tendon="right" dyntype="user" gaintype="user" biastype="user"/>
  </actuator>
</mujoco>)";
  ModelPtr m = MustLoad(xml);
  auto p = MustCreate(m.get());
  ASSERT_EQ(p->num_bundles(), 2);
  const int fl = p->BundleIndex("flexor"), ex = p->BundleIndex("extensor");
  EXPECT_EQ(p->num_units(fl), 30);
  EXPECT_EQ(p->num_units(ex), 40);
  EXPECT_EQ(p->tendon_id(fl), mj_name2id(m.get(), mjOBJ_TENDON, "left"));
  EXPECT_EQ(p->tendon_id(ex), mj_name2id(m.get(), mjOBJ_TENDON, "right"));
  EXPECT_EQ(p->actuator_id(ex), 2);
  EXPECT_EQ(*SmaPlugin::RequiredUserdata(m.get()), (8 + 8 * 30) + (8 + 8 * 40));
  DataPtr d = MakeData(m.get());
  p->Reset(d.get(), 2);
  ASSERT_TRUE(p->Broadcast(d.get(), fl, 1, 0).ok());
  EXPECT_EQ(p->OnCount(d.get(), fl), 30);
  EXPECT_EQ(p->OnCount(d.get(), ex), 0);
  EXPECT_EQ(d->act[0], 1.0);  // acts of the two user actuators, in actuator order
  EXPECT_EQ(d->act[1], 0.0);
  for (int i = 0; i < 3000; ++i) Step(m.get(), d.get(), *p);
  EXPECT_GT(p->Force(d.get(), fl), 1.0);
  EXPECT_EQ(p->OnCount(d.get(), ex), 0);
  EXPECT_LT(p->MeanTemperature(d.get(), ex), 20.001);
  EXPECT_LT(d->qpos[0], 0);              // the flexor pulled the slider towards its anchor
  EXPECT_EQ(d->actuator_force[0], 0.0);  // the motor is not ours: zero ctrl, zero force
  EXPECT_FALSE(p->Broadcast(d.get(), 2, 0.5, 0.5).ok());
}

}  // namespace
}  // namespace recruit::sma

namespace recruit::sma {
namespace {

TEST(Registry, PluginsCreatedAndDestroyedWhileOtherThreadsStep) {
  ModelPtr stepping = MustLoad(BenchXml());
  std::vector<ModelPtr> churn;
  for (int k = 0; k < 4; ++k) churn.push_back(MustLoad(BenchXml()));
  auto p = MustCreate(stepping.get());
  std::atomic<bool> done{false};
  std::thread creator([&] {
    for (int round = 0; round < 40; ++round) {
      std::vector<std::unique_ptr<SmaPlugin>> live;
      for (auto& m : churn) live.push_back(MustCreate(m.get()));
    }
    done = true;
  });
  DataPtr d = MakeData(stepping.get()), ref = MakeData(stepping.get());
  p->Reset(d.get(), 5);
  p->Reset(ref.get(), 5);
  ASSERT_TRUE(p->Broadcast(d.get(), 0, 0.7, 0).ok());
  ASSERT_TRUE(p->Broadcast(ref.get(), 0, 0.7, 0).ok());
  int steps = 0;
  while (!done || steps < 2000) {
    Step(stepping.get(), d.get(), *p);
    ++steps;
  }
  creator.join();
  for (int i = 0; i < steps; ++i) Step(stepping.get(), ref.get(), *p);
  EXPECT_EQ(d->qpos[0], ref->qpos[0]);
  EXPECT_EQ(p->Force(d.get(), 0), p->Force(ref.get(), 0));
}

}  // namespace
}  // namespace recruit::sma

namespace recruit::sma {
namespace {

TEST(HostApi, UserdataAddressLeavesTheHostsOwnEntriesAlone) {
  const std::string xml = Replace(BenchXml("units=60", 498), "<custom>",
                                  "<custom><numeric name=\"recruit.sma.userdata_address\" "
                                  "data=\"10\"/>");
  ModelPtr m = MustLoad(xml);
  auto need = SmaPlugin::RequiredUserdata(m.get());
  ASSERT_TRUE(need.ok()) << need.error();
  EXPECT_EQ(*need, 10 + 8 + 8 * 60);
  auto p = MustCreate(m.get());
  DataPtr d = MakeData(m.get());
  for (int i = 0; i < 10; ++i) d->userdata[i] = 100 + i;
  p->Reset(d.get(), 1);
  ASSERT_TRUE(p->Broadcast(d.get(), 0, 1, 0).ok());
  for (int i = 0; i < 2000; ++i) Step(m.get(), d.get(), *p);
  for (int i = 0; i < 10; ++i) EXPECT_EQ(d->userdata[i], 100 + i);
  EXPECT_GT(p->Force(d.get(), 0), 5.0);
}

TEST(HostApi, UserdataAddressMustBeAWholeNonNegativeNumber) {
  for (const char* bad : {"-1", "2.5"}) {
    const std::string xml =
        Replace(BenchXml("units=60", 600), "<custom>",
                std::string("<custom><numeric name=\"recruit.sma.userdata_address\" data=\"") +
                    bad + "\"/>");
    ModelPtr m = MustLoad(xml);
    auto p = SmaPlugin::Create(m.get());
    ASSERT_FALSE(p.ok()) << bad;
    EXPECT_THAT(p.error(), HasSubstr("recruit.sma.userdata_address"));
    EXPECT_THAT(p.error(), HasSubstr("whole number >= 0"));
  }
}

}  // namespace
}  // namespace recruit::sma
