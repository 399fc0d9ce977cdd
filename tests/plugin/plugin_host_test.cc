// The host API (SmaHost, linked library) against what the engine plugin itself reports through
// its sensor, and the fit check of bundles on a model the project did not write.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <string>
#include <vector>

#include "common/rng.h"
#include "plugin/sma_host.h"
#include "plugin/sma_instance.h"
#include "tests/plugin/mujoco_util.h"

namespace recruit::sma {
namespace file_plugin_host_test {

using testing::DataPtr;
using ::testing::HasSubstr;
using testing::ModelPtr;

// (f) The plugin sensor (count, tension, mean T, mean xi per bundle) equals the host API's
// OnCount, Force, MeanTemperature and MeanXi exactly, on the two-bundle elbow arm while the
// bundles switch at random and the elbow moves.
TEST(PluginSensor, ReportsWhatTheHostApiReads) {
  testing::WarningCapture fit_warnings;  // elbow_arm.xml's units do not fit its tendons
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

// The sensor keeps its tension for the actuator's force in the same mj_forward (issue 15): the
// dynamics are those of a run whose sensors are disabled (the force then always summed afresh),
// bit for bit, under Euler and RK4 (whose later stages compute the force without the sensor);
// a full mj_forward leaves plugin_state as it was; the actuator force is minus Force.
TEST(PluginSensor, KeptTensionChangesNothingWithOrWithoutSensorsUnderEulerAndRk4) {
  testing::WarningCapture fit_warnings;  // elbow_arm.xml's units do not fit its tendons
  auto m = LoadModel(RECRUIT_SOURCE_DIR "/models/elbow_arm.xml");
  ASSERT_TRUE(m.ok()) << m.error();
  mjModel* mm = m->get();
  auto host = SmaHost::Create(mm);
  ASSERT_TRUE(host.ok()) << host.error();
  const SmaHost& h = **host;
  DataPtr with(mj_makeData(mm)), without(mj_makeData(mm));
  h.Reset(with.get(), 8);
  h.Reset(without.get(), 8);
  auto same = [](const double* a, const double* b, int n) {
    return std::memcmp(a, b, n * sizeof(double)) == 0;
  };
  Rng rng(4);
  const int flags = mm->opt.disableflags;
  int checks = 0;
  for (int step = 0; step < 4000; ++step) {
    mm->opt.integrator = step < 2000 ? mjINT_EULER : mjINT_RK4;
    if (step % 50 == 0) {
      const double p_on = 0.3 * rng.Uniform(), p_off = 0.2 * rng.Uniform();
      for (mjData* d : {with.get(), without.get()}) {
        for (int b = 0; b < h.num_bundles(); ++b) ASSERT_TRUE(h.Broadcast(d, b, p_on, p_off).ok());
      }
    }
    mm->opt.disableflags = flags;
    mj_step(mm, with.get());
    mm->opt.disableflags = flags | mjDSBL_SENSOR;
    mj_step(mm, without.get());
    mm->opt.disableflags = flags;
    ASSERT_TRUE(same(with->qpos, without->qpos, mm->nq)) << "step " << step;
    ASSERT_TRUE(same(with->qvel, without->qvel, mm->nv)) << "step " << step;
    ASSERT_TRUE(same(with->plugin_state, without->plugin_state, mm->npluginstate))
        << "step " << step;
    if (step % 41 != 0) continue;
    const std::vector<double> before(with->plugin_state, with->plugin_state + mm->npluginstate);
    mj_forward(mm, with.get());
    EXPECT_TRUE(same(before.data(), with->plugin_state, mm->npluginstate)) << "step " << step;
    for (int b = 0; b < h.num_bundles(); ++b) {
      EXPECT_EQ(with->actuator_force[h.actuator_id(b)], -h.Force(with.get(), b));
    }
    ++checks;
  }
  EXPECT_GT(checks, 90);
  EXPECT_GT(h.OnCount(with.get(), 0) + h.OnCount(with.get(), 1), 0);
}

// Issue 15: the Fig. 4 trace of `sma_fig4_step models/isometric_bench.xml 12 20` (on at 1 s,
// off at 12 s, through MuJoCo with the load cell) is unchanged by the batched cohort update:
// values recorded (printf %.17g) from the previous implementation, the scalar per-cohort update
// (commit 00dea36). They were bit-identical at every one of the 20000 steps in the portable and
// the x86-64-v3 builds; the test allows 1e-12 relative.
TEST(PluginFig4, TraceUnchangedFromScalarImplementation) {
  struct Row {
    double t, force, mean_t, mean_xi;
  };
  const Row want[] = {
      {1.000, 0, 20, 1},
      {1.500, 0, 50.500363244056764, 1},
      {2.000, 0.20551736423755201, 68.610157933675509, 0.99206543793901203},
      {2.500, 8.6436479442751608, 73.667135593642541, 0.67138521704045473},
      {3.000, 18.749645021158262, 78.216050267106581, 0.29378935654747568},
      {4.000, 26.661645102248102, 97.862195150765146, 0},
      {8.000, 26.661645102248102, 115.28402903704384, 0},
      {12.000, 26.661645102248102, 115.58113024336328, 0},
      {12.500, 26.661645102248102, 77.457732100060767, 0},
      {13.000, 25.400420308256837, 55.845909968360438, 0.04673799866608281},
      {13.500, 14.838441190484893, 50.443620234986653, 0.43943930118005708},
      {14.000, 5.5152438119654414, 46.172296479151605, 0.7893001790104639},
      {15.000, 0, 32.12770938192952, 1},
      {20.000, 0, 20.074738084805009, 1},
  };
  auto m = LoadModel(RECRUIT_SOURCE_DIR "/models/isometric_bench.xml");
  ASSERT_TRUE(m.ok()) << m.error();
  const mjModel* mm = m->get();
  auto host = SmaHost::Create(mm);
  ASSERT_TRUE(host.ok()) << host.error();
  const SmaHost& p = **host;
  DataPtr d(mj_makeData(mm));
  p.Reset(d.get(), 1);
  // The protocol of plugin/examples/fig4_step.cc.
  bool on = false, off = false;
  size_t k = 0;
  while (d->time < 20 - 1e-9) {
    if (!on && d->time >= 1.0 - 1e-9) {
      ASSERT_TRUE(p.Broadcast(d.get(), 0, 1.0, 0.0).ok());
      on = true;
    }
    if (!off && d->time >= 12 - 1e-9) {
      ASSERT_TRUE(p.Broadcast(d.get(), 0, 0.0, 1.0).ok());
      off = true;
    }
    mj_step(mm, d.get());
    if (k < std::size(want) && std::abs(d->time - want[k].t) < 1e-9) {
      auto rel = [](double got, double w) {
        return std::abs(got - w) / std::max(std::abs(w), 1.0);
      };
      EXPECT_LE(rel(p.Force(d.get(), 0), want[k].force), 1e-12) << "t " << want[k].t;
      EXPECT_LE(rel(p.MeanTemperature(d.get(), 0), want[k].mean_t), 1e-12) << "t " << want[k].t;
      EXPECT_LE(rel(p.MeanXi(d.get(), 0), want[k].mean_xi), 1e-12) << "t " << want[k].t;
      ++k;
    }
  }
  EXPECT_EQ(k, std::size(want));
}

// A two-joint arm written for this test after the structure of MuJoCo's
// model/tendon_arm/arm26.xml (shoulder and elbow hinges, tendons on sites with wrapping
// cylinders and side sites, here plus a fixed tendon); no geometry copied. The project did not
// design it for SMA bundles: it is the "model written elsewhere" of issue 9 item 8.
// `biceps` crosses both joints around the elbow cylinder; `brachialis` is a fixed tendon,
// length = 0.02 * elbow angle (rad), so its excursion over the elbow's 0..120 deg range is
// exactly 0.02 * 2.0944 = 41.9 mm.
std::string Arm26Like(const std::string& biceps_config, const std::string& brachialis_config) {
  return R"(<mujoco model="arm26_like">
  <compiler angle="degree" autolimits="true"/>
  <option timestep="0.002"/>
  <extension><plugin plugin="recruit.sma">
    <instance name="biceps_units">)" +
         biceps_config + R"(</instance>
    <instance name="brachialis_units">)" +
         brachialis_config + R"(</instance>
  </plugin></extension>
  <worldbody>
    <site name="s_origin" pos="0.02 0 0.15"/>
    <body name="upper_arm" pos="0 0 0">
      <joint name="shoulder" type="hinge" axis="0 1 0" range="-60 60" damping="0.5"/>
      <geom name="humerus" type="capsule" fromto="0 0 0 0.3 0 0" size="0.02" mass="1.5"/>
      <geom name="shoulder_wrap" type="cylinder" pos="0 0 0" size="0.04 0.02"
            zaxis="0 1 0" contype="0" conaffinity="0"/>
      <site name="shoulder_side" pos="0 0 0.06"/>
      <site name="b_mid" pos="0.15 0 0.03"/>
      <body name="forearm" pos="0.3 0 0">
        <joint name="elbow" type="hinge" axis="0 -1 0" range="0 120" damping="0.5"/>
        <geom name="radius" type="capsule" fromto="0 0 0 0.25 0 0" size="0.015" mass="1"/>
        <geom name="elbow_wrap" type="cylinder" pos="0 0 0" size="0.025 0.02"
              zaxis="0 1 0" contype="0" conaffinity="0"/>
        <site name="elbow_side" pos="0 0 0.05"/>
        <site name="b_insertion" pos="0.05 0 0.015"/>
      </body>
    </body>
  </worldbody>
  <tendon>
    <spatial name="biceps">
      <site site="s_origin"/>
      <geom geom="shoulder_wrap" sidesite="shoulder_side"/>
      <site site="b_mid"/>
      <geom geom="elbow_wrap" sidesite="elbow_side"/>
      <site site="b_insertion"/>
    </spatial>
    <fixed name="brachialis"><joint joint="elbow" coef="0.02"/></fixed>
  </tendon>
  <actuator>
    <plugin name="biceps" instance="biceps_units" tendon="biceps" ctrlrange="-1 1"/>
    <plugin name="brachialis" instance="brachialis_units" tendon="brachialis"
            ctrlrange="-1 1"/>
  </actuator>
</mujoco>)";
}

std::vector<TendonFit> FitsOf(const mjModel* m) {
  std::vector<TendonFit> all;
  for (int i = 0; i < m->nplugin; ++i) {
    auto inst = SmaInstance::Create(m, i);
    EXPECT_TRUE(inst.ok()) << inst.error();
    if (!inst.ok()) continue;
    for (const TendonFit& f : (*inst)->Fit(m)) all.push_back(f);
  }
  return all;
}

// Issue 9 item 8: default units (4 mm stroke) on tendons that move tens of millimetres warn at
// load time with the numbers, and the numbers are right: the fixed tendon's excursion is
// coef x range; the spatial tendon's range matches a dense sweep of both joints; the off
// units' pull is N k_M (extension - stroke) with k_M the martensite wire (E_M A / L) in series
// with the coupling spring; the suggested series/prestretch make both bundles fit.
TEST(FitCheck, WarnsWithTheNumbersOnAModelWrittenElsewhere) {
  testing::WarningCapture warnings;
  auto m = LoadModelFromString(Arm26Like("", ""));
  ASSERT_TRUE(m.ok()) << m.error();
  const mjModel* mm = m->get();
  const std::string text = warnings.joined();
  EXPECT_THAT(text, HasSubstr("recruit.sma actuator 'biceps': tendon excursion"));
  EXPECT_THAT(text, HasSubstr("recruit.sma actuator 'brachialis': tendon excursion 41.9 mm over "
                              "elbow 0..120 deg, unit stroke 4.0 mm, extension 4.0..45.9 mm"));
  EXPECT_THAT(text, HasSubstr("will block the joint"));
  EXPECT_THAT(text, HasSubstr("fit: series=11"));  // ceil(41.9 / 4)

  const std::vector<TendonFit> fits = FitsOf(mm);
  ASSERT_EQ(fits.size(), 2u);
  const TendonFit& bra = fits[1];
  EXPECT_EQ(bra.joints, 1);
  EXPECT_NEAR(bra.excursion(), 0.02 * 120 * mjPI / 180, 1e-12);
  // closed-form off pull at the longest tendon (qpos0 = 0 is the shortest: ref length there)
  const UnitParams u;
  const double area = mjPI / 4 * u.wire_diameter * u.wire_diameter;
  const double k_wire = u.E_M * area / u.wire_length;
  const double k_off = 1 / (1 / k_wire + 1 / u.series_spring);
  const double stroke = u.eps_L * u.wire_length;
  EXPECT_NEAR(bra.stroke, stroke, 1e-15);
  EXPECT_NEAR(bra.stretch_max, u.prestretch + bra.excursion(), 1e-12);
  EXPECT_NEAR(bra.off_force, 60 * k_off * (bra.stretch_max - stroke), 1e-9);
  EXPECT_TRUE(bra.blocks());

  // The biceps' range against a dense sweep (201 x 201) of both joints with mj_fwdPosition.
  const TendonFit& bic = fits[0];
  EXPECT_EQ(bic.joints, 2);
  DataPtr d(mj_makeData(mm));
  double lo = INFINITY, hi = -INFINITY;
  const int t = mj_name2id(mm, mjOBJ_TENDON, "biceps");
  for (int i = 0; i <= 200; ++i) {
    for (int j = 0; j <= 200; ++j) {
      d->qpos[0] = mm->jnt_range[0] + i / 200.0 * (mm->jnt_range[1] - mm->jnt_range[0]);
      d->qpos[1] = mm->jnt_range[2] + j / 200.0 * (mm->jnt_range[3] - mm->jnt_range[2]);
      mj_fwdPosition(mm, d.get());
      lo = std::min(lo, d->ten_length[t]);
      hi = std::max(hi, d->ten_length[t]);
    }
  }
  EXPECT_GT(hi - lo, 0.02);  // tens of millimetres: far more than a 4 mm stroke
  // the check's coarser grid (65 x 65) finds the range within 1.5 % of the excursion
  EXPECT_NEAR(bic.length_min, lo, 0.015 * (hi - lo));
  EXPECT_NEAR(bic.length_max, hi, 0.015 * (hi - lo));
  EXPECT_TRUE(bic.blocks() || bic.slack());

  // The suggested geometry fits: no warning, both bundles within their stroke.
  auto config = [](const TendonFit& f) {
    char p[64];
    std::snprintf(p, sizeof p, "%.17g", f.prestretch_needed);
    return "<config key=\"series\" value=\"" + std::to_string(f.series_needed) +
           "\"/><config key=\"prestretch\" value=\"" + p + "\"/>";
  };
  testing::WarningCapture quiet;
  auto fixed = LoadModelFromString(Arm26Like(config(bic), config(bra)));
  ASSERT_TRUE(fixed.ok()) << fixed.error();
  EXPECT_EQ(quiet.joined(), "");
  // once per distinct model: another mjData of the same model checks (and warns) nothing more
  testing::WarningCapture again;
  DataPtr d2(mj_makeData(mm));
  EXPECT_EQ(again.joined(), "");
  for (const TendonFit& f : FitsOf(fixed->get())) {
    EXPECT_TRUE(f.fits()) << f.stretch_min << " " << f.stretch_max << " " << f.stroke;
  }
}

// A bench whose only joint is unlimited (the isometric load cell) has nothing to check.
TEST(FitCheck, UnlimitedJointsAreNotChecked) {
  testing::WarningCapture warnings;
  auto m = LoadModel(RECRUIT_SOURCE_DIR "/models/isometric_bench.xml");
  ASSERT_TRUE(m.ok()) << m.error();
  const std::vector<TendonFit> fits = FitsOf(m->get());
  ASSERT_EQ(fits.size(), 1u);
  EXPECT_EQ(fits[0].joints, 0);
  EXPECT_TRUE(fits[0].fits());
  EXPECT_EQ(warnings.joined(), "");
}

// Over one joint the range comes from 33 points and a golden-section search at each interior
// extreme: a two-site tendon whose length has its minimum inside the joint's range (off the
// grid) and another whose length has its maximum there, against the law of cosines. Site A is
// fixed at distance 0.2 m from a vertical hinge, site B turns with it at 0.1 m: the length is
// sqrt(0.05 - 0.04 cos(q - q_B)), q in -50..70 deg.
TEST(FitCheck, FindsAnExtremeInsideTheRangeOfOneJoint) {
  auto model = [](const char* b_pos) {
    return std::string(R"(<mujoco>
  <compiler angle="degree" autolimits="true"/>
  <extension><plugin plugin="recruit.sma"><instance name="units"/></plugin></extension>
  <worldbody>
    <site name="a" pos="0.2 0 0"/>
    <body name="arm">
      <joint name="turn" type="hinge" axis="0 0 1" range="-50 70"/>
      <geom type="sphere" size="0.01" mass="0.1" contype="0" conaffinity="0"/>
      <site name="b" pos=")") +
           b_pos + R"("/>
    </body>
  </worldbody>
  <tendon><spatial name="t"><site site="a"/><site site="b"/></spatial></tendon>
  <actuator><plugin name="m" instance="units" tendon="t" ctrlrange="-1 1"/></actuator>
</mujoco>)";
  };
  auto length = [](double q_deg) { return std::sqrt(0.05 - 0.04 * std::cos(q_deg * mjPI / 180)); };
  testing::WarningCapture warnings;  // the default units do not fit: not the point here
  // B toward A at q = 0: the shortest length (0.1 m) at q = 0, 13.3 grid steps from -50 deg.
  auto near = LoadModelFromString(model("0.1 0 0"));
  ASSERT_TRUE(near.ok()) << near.error();
  std::vector<TendonFit> fits = FitsOf(near->get());
  ASSERT_EQ(fits.size(), 1u);
  EXPECT_EQ(fits[0].joints, 1);
  EXPECT_NEAR(fits[0].length_min, 0.1, 1e-10);
  EXPECT_NEAR(fits[0].length_max, length(70), 1e-12);
  // B away from A at q = 0: the longest length (0.3 m) there.
  auto far = LoadModelFromString(model("-0.1 0 0"));
  ASSERT_TRUE(far.ok()) << far.error();
  fits = FitsOf(far->get());
  ASSERT_EQ(fits.size(), 1u);
  EXPECT_NEAR(fits[0].length_max, 0.3, 1e-10);
  EXPECT_NEAR(fits[0].length_min, length(180 - 70), 1e-12);
}

}  // namespace file_plugin_host_test
// The fit warning's lists are cut between entries, never inside a joint's range.
TEST(FitCheck, WarningListsAreCutBetweenEntries) {
  const std::string ranges = "shoulder 0..111.8 deg, elbow 0..114.4 deg, wrist -70..70 deg";
  EXPECT_EQ(ClipEntries(ranges, 100), ranges);
  EXPECT_EQ(ClipEntries(ranges, 48), "shoulder 0..111.8 deg, elbow 0..114.4 deg, ...");
  EXPECT_EQ(ClipEntries(ranges, 30), "shoulder 0..111.8 deg, ...");
  EXPECT_EQ(ClipEntries("shoulder at 1.2 deg; elbow at 114.4 deg", 25), "shoulder at 1.2 deg; ...");
  EXPECT_EQ(ClipEntries("averyveryverylongjointname", 10), "averyveryv...");
}

}  // namespace recruit::sma
