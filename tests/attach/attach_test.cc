// recruit attach (src/attach) and the jump-aware tendon range (plugin/tendon_range): the written
// model loads with MuJoCo's own loader and keeps every other element, the sizing against closed
// forms, path jumps against a dense sweep, the gear transmission against its closed form.
#include "attach/attach.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "attach/damper.h"
#include "attach/holding_load.h"
#include "attach/sizing.h"
#include "common/mujoco_load.h"
#include "plugin/sma_host.h"
#include "plugin/sma_plugin.h"
#include "plugin/tendon_range.h"
#include "sim/csv_writer.h"
#include "sim/holding.h"
#include "sim/plant.h"
#include "sim/run_task.h"
#include "sim/task.h"
#include "tests/plugin/mujoco_util.h"

namespace recruit::attach {
namespace {

namespace fs = std::filesystem;

const std::string kSrc = RECRUIT_SOURCE_DIR;

std::string TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("recruit_attach_test_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

ModelPtr Load(const std::string& path) {
  sma::RegisterSmaPlugin();
  auto m = LoadModel(path);
  EXPECT_TRUE(m.ok()) << m.error();
  return m.ok() ? std::move(m).value() : nullptr;
}

// The original compiled without lengthrange computation (what attach probes).
ModelPtr LoadPlain(const std::string& path) {
  char error[1000] = "";
  mjSpec* s = mj_parseXML(path.c_str(), nullptr, error, sizeof error);
  EXPECT_NE(s, nullptr) << error;
  s->compiler.LRopt.mode = mjLRMODE_NONE;
  ModelPtr m(mj_compile(s, nullptr));
  mj_deleteSpec(s);
  return m;
}

TEST(Attach, TwoJointArmAllMusclesLoadsAndKeepsEverythingElse) {
  const std::string in = kSrc + "/models/arm2j_muscle.xml";
  const std::string dir = TempDir("arm2j");
  AttachOptions o;
  o.model = in;
  o.muscles = {"all"};
  o.output = dir + "/arm2j_sma.xml";
  o.task = dir + "/task.json";
  auto r = Attach(o);
  ASSERT_TRUE(r.ok()) << r.error();
  ModelPtr before = Load(in);
  ModelPtr after = Load(o.output);  // MuJoCo's own loader, plugin registered
  ASSERT_TRUE(before && after);
  EXPECT_EQ(after->nbody, before->nbody);
  EXPECT_EQ(after->njnt, before->njnt);
  EXPECT_EQ(after->ngeom, before->ngeom);
  EXPECT_EQ(after->nsite, before->nsite);
  EXPECT_EQ(after->ntendon, before->ntendon);
  EXPECT_EQ(after->nu, before->nu);
  EXPECT_EQ(after->nsensor, before->nsensor + 6);
  for (int b = 0; b < before->nbody; ++b) EXPECT_EQ(after->body_mass[b], before->body_mass[b]);
  for (int j = 0; j < before->njnt; ++j) {
    // mj_saveXML writes 6 significant digits (the compiled radians of a degree model).
    EXPECT_NEAR(after->jnt_range[2 * j], before->jnt_range[2 * j], 1e-5);
    EXPECT_EQ(after->dof_damping[j], before->dof_damping[j]);
  }
  EXPECT_EQ(after->opt.timestep, before->opt.timestep);
  ASSERT_EQ(r->bundles.size(), 6u);
  for (const BundleReport& b : r->bundles) {
    const int a = mj_name2id(after.get(), mjOBJ_ACTUATOR, b.name.c_str());
    const int a0 = mj_name2id(before.get(), mjOBJ_ACTUATOR, b.name.c_str());
    ASSERT_GE(a, 0);
    EXPECT_EQ(after->actuator_trnid[2 * a], before->actuator_trnid[2 * a0]) << b.name;
    EXPECT_GE(after->actuator_plugin[a], 0);
    EXPECT_EQ(after->actuator_dyntype[a], mjDYN_NONE);  // not the inherited muscle default
    EXPECT_EQ(after->actuator_actnum[a], 0);
    EXPECT_EQ(after->actuator_gear[6 * a], b.design.gear);
    EXPECT_GE(mj_name2id(after.get(), mjOBJ_SENSOR, b.sensor.c_str()), 0);
  }
  // The host sees the bundles with the designed sizes.
  auto host = sma::SmaHost::Create(after.get());
  ASSERT_TRUE(host.ok()) << host.error();
  EXPECT_EQ((*host)->num_bundles(), 6);
  EXPECT_TRUE(fs::exists(o.task));
}

// The dampers: MuJoCo's own passive force at a unit joint velocity (qfrc_damper of the written
// model, at qpos0) is the damping the report gives each joint, and it brings every moved joint to
// the ratio asked at the bundles' rest stiffness; the ratio 0 writes none.
TEST(Attach, DampersGiveEveryMovedJointTheRatioAsked) {
  const std::string in = kSrc + "/models/arm2j_muscle.xml";
  for (double ratio : {0.0, 0.5, 1.2}) {
    const std::string dir = TempDir("dampers");
    AttachOptions o;
    o.model = in;
    o.muscles = {"all"};
    o.output = dir + "/arm2j_sma.xml";
    o.limits.damping_ratio = ratio;
    auto r = Attach(o);
    ASSERT_TRUE(r.ok()) << r.error();
    ModelPtr m = Load(o.output);
    ASSERT_TRUE(m);
    ASSERT_EQ(r->damped_joints.size(), 2u);
    std::unique_ptr<mjData, void (*)(mjData*)> d(mj_makeData(m.get()), mj_deleteData);
    for (const DampedJoint& j : r->damped_joints) {
      const int id = mj_name2id(m.get(), mjOBJ_JOINT, j.joint.c_str());
      ASSERT_GE(id, 0) << j.joint;
      mj_resetData(m.get(), d.get());
      d->qvel[m->jnt_dofadr[id]] = 1;
      mj_forward(m.get(), d.get());
      EXPECT_NEAR(-d->qfrc_damper[m->jnt_dofadr[id]], j.damping_after, 1e-5 * j.damping_after)
          << j.joint << " ratio " << ratio;
      EXPECT_GE(j.ratio_after, std::max(ratio, j.ratio_before) - 1e-9) << j.joint;
      EXPECT_EQ(j.damping, m->dof_damping[m->jnt_dofadr[id]]);  // the limb had no other damper
    }
    // Some joint is at the ratio exactly (the one that asked most) unless none needed any.
    double least = 1e9;
    for (const DampedJoint& j : r->damped_joints) {
      if (j.ratio_after > j.ratio_before + 1e-12) least = std::min(least, j.ratio_after);
    }
    if (least < 1e9) {
      EXPECT_NEAR(least, ratio, 1e-9);
    }
    for (const BundleReport& b : r->bundles) {
      const int a = mj_name2id(m.get(), mjOBJ_ACTUATOR, b.name.c_str());
      EXPECT_NEAR(m->actuator_damping[a], b.design.damper, 1e-5 * b.design.damper) << b.name;
      if (ratio == 0) {
        EXPECT_EQ(b.design.damper, 0.0);
      }
    }
  }
}

TEST(Attach, OtherActuatorsKeepTheirParameters) {
  const std::string in = kSrc + "/models/arm2j_muscle.xml";
  const std::string dir = TempDir("arm2j_ef");
  AttachOptions o;
  o.model = in;
  o.muscles = {"EF", "EE"};
  o.output = dir + "/out.xml";
  auto r = Attach(o);
  ASSERT_TRUE(r.ok()) << r.error();
  ModelPtr before = Load(in), after = Load(o.output);
  ASSERT_TRUE(before && after);
  for (const char* name : {"SF", "SE", "BF", "BE"}) {
    const int a = mj_name2id(after.get(), mjOBJ_ACTUATOR, name);
    const int a0 = mj_name2id(before.get(), mjOBJ_ACTUATOR, name);
    EXPECT_EQ(after->actuator_dyntype[a], before->actuator_dyntype[a0]);
    EXPECT_EQ(after->actuator_gaintype[a], before->actuator_gaintype[a0]);
    for (int k = 0; k < mjNGAIN; ++k) {
      EXPECT_EQ(after->actuator_gainprm[mjNGAIN * a + k],
                before->actuator_gainprm[mjNGAIN * a0 + k]);
    }
    EXPECT_NEAR(after->actuator_lengthrange[2 * a], before->actuator_lengthrange[2 * a0], 1e-5);
    EXPECT_NEAR(after->actuator_lengthrange[2 * a + 1], before->actuator_lengthrange[2 * a0 + 1],
                1e-5);
  }
}

TEST(Attach, BadInputIsRefusedAndNothingIsWritten) {
  const std::string in = kSrc + "/models/arm2j_muscle.xml";
  const std::string dir = TempDir("bad");
  AttachOptions o;
  o.model = in;
  o.output = dir + "/out.xml";
  o.muscles = {"biceps"};
  auto r = Attach(o);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("'biceps' does not exist"), std::string::npos) << r.error();
  EXPECT_NE(r.error().find("SF, SE"), std::string::npos) << r.error();
  o.model = kSrc + "/tests/attach/data/jump_arm.xml";
  o.muscles = {"elbow_motor"};
  r = Attach(o);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("does not act on a tendon"), std::string::npos) << r.error();
  o.muscles = {"ext"};
  o.output = o.model;
  r = Attach(o);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("refusing to overwrite"), std::string::npos) << r.error();
  o.model = dir + "/missing.xml";
  o.output = dir + "/out.xml";
  r = Attach(o);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("cannot open"), std::string::npos);
  EXPECT_TRUE(fs::is_empty(dir));
}

TEST(Attach, OtherMusclesFailingLengthrangeAreNamedAndFixedFromJoints) {
  const std::string in = kSrc + "/tests/attach/data/jump_arm.xml";
  const std::string dir = TempDir("lr");
  AttachOptions o;
  o.model = in;
  o.muscles = {"flx"};
  o.output = dir + "/out.xml";
  auto r = Attach(o);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("muscle(s) ext"), std::string::npos) << r.error();
  EXPECT_NE(r.error().find("--lengthrange-from-joints"), std::string::npos);
  EXPECT_TRUE(fs::is_empty(dir));
  o.lengthrange_from_joints = true;
  r = Attach(o);
  ASSERT_TRUE(r.ok()) << r.error();
  ASSERT_EQ(r->lengthranges.size(), 1u);
  EXPECT_EQ(r->lengthranges[0].actuator, "ext");
  ModelPtr m = Load(o.output);
  ASSERT_TRUE(m);
  const int a = mj_name2id(m.get(), mjOBJ_ACTUATOR, "ext");
  // 6 significant digits in the written MJCF.
  EXPECT_NEAR(m->actuator_lengthrange[2 * a], r->lengthranges[0].lo, 1e-6);
  EXPECT_NEAR(m->actuator_lengthrange[2 * a + 1], r->lengthranges[0].hi, 1e-6);
}

// Jumps against a dense independent sweep of the same joint.
TEST(TendonRange, FindsThePathJumpAndSizesOnTheUsableSide) {
  ModelPtr m = LoadPlain(kSrc + "/tests/attach/data/jump_arm.xml");
  ASSERT_TRUE(m);
  DataPtr d(mj_makeData(m.get()));
  const int t = mj_name2id(m.get(), mjOBJ_TENDON, "ext");
  const sma::TendonRange r = sma::SampleTendonRange(m.get(), d.get(), t);
  ASSERT_EQ(r.jumps.size(), 1u);
  const double at = r.jumps[0].at;
  // Dense sweep: the largest step between neighbours is where the jump is.
  const int n = 20001;
  double lo = INFINITY, hi = -INFINITY, biggest = 0, where = 0, prev = 0;
  for (int i = 0; i < n; ++i) {
    const double q = m->jnt_range[1] * i / (n - 1);
    d->qpos[0] = q;
    mj_kinematics(m.get(), d.get());
    mj_comPos(m.get(), d.get());
    mj_tendon(m.get(), d.get());
    const double l = d->ten_length[t];
    if (i > 0 && std::abs(l - prev) > biggest) biggest = std::abs(l - prev), where = q;
    if (q < at) lo = std::min(lo, l), hi = std::max(hi, l);
    prev = l;
  }
  EXPECT_NEAR(at, where, m->jnt_range[1] / (n - 1));
  EXPECT_GT(std::abs(r.jumps[0].after - r.jumps[0].before), 0.9 * biggest);
  EXPECT_NEAR(r.usable_hi[0], at, 1e-6);
  EXPECT_EQ(r.usable_lo[0], 0.0);
  EXPECT_NEAR(r.length_min, lo, 1e-6);
  EXPECT_NEAR(r.length_max, hi, 1e-6);
  // The smooth flexor has none.
  const sma::TendonRange f =
      sma::SampleTendonRange(m.get(), d.get(), mj_name2id(m.get(), mjOBJ_TENDON, "flx"));
  EXPECT_TRUE(f.jumps.empty());
}

// Sizing: closed forms of the straight wire in series with its coupling spring.
// A large force: the thinnest wire with at most 2 per segment is slow; the bandwidth rule takes
// a thinner wire with more of them (faster, hotter bill), and a looser rule keeps the thick one.
TEST(Sizing, TheBandwidthRuleTradesHeatingPowerForTheTimeConstant) {
  SizingInput in{"b", 900, 0.04, 0.1, 0.14, 0.12};
  auto fast = SizeBundle(in);
  ASSERT_TRUE(fast.ok()) << fast.error();
  SizingLimits loose;
  loose.max_time_constant = 100;
  auto slow = SizeBundle(in, loose);
  ASSERT_TRUE(slow.ok()) << slow.error();
  EXPECT_LE(fast->time_constant, 2.0);
  EXPECT_GT(slow->time_constant, 2.0);
  EXPECT_LT(fast->unit.wire_diameter, slow->unit.wire_diameter);
  EXPECT_LE(slow->unit.parallel, 2);
  EXPECT_LE(fast->unit.parallel, loose.max_parallel);
  EXPECT_GT(fast->power, slow->power);
  // Both meet the force.
  EXPECT_GE(fast->force_mid, 900);
  EXPECT_GE(slow->force_mid, 900);
}

// A force no fast-enough wire makes within max_units_fast units takes up to max_units_resolution
// of them before a slow wire; past that the slow design says so in its notes.
TEST(Sizing, TheBandwidthRuleTakesMoreUnitsBeforeASlowWireAndSaysWhenItCannot) {
  SizingLimits limits;
  limits.units_per_holding_force = 0;  // the resolution rule off: the bandwidth rule alone
  auto slow_note = [](const BundleDesign& d) {
    for (const std::string& n : d.notes) {
      if (n.find("thermal time constant") != std::string::npos) return true;
    }
    return false;
  };
  SizingInput big{"b", 4000, 0.04, 0.1, 0.14, 0.12};
  auto many = SizeBundle(big, limits);
  ASSERT_TRUE(many.ok()) << many.error();
  EXPECT_LE(many->time_constant, limits.max_time_constant);
  EXPECT_GT(many->units, limits.max_units_fast);
  EXPECT_LE(many->units, limits.max_units_resolution);
  EXPECT_LE(many->unit.parallel, limits.max_parallel);
  EXPECT_GE(many->force_mid, 4000);
  EXPECT_FALSE(slow_note(*many));
  SizingInput huge{"b", 8000, 0.04, 0.1, 0.14, 0.12};
  auto slow = SizeBundle(huge, limits);
  ASSERT_TRUE(slow.ok()) << slow.error();
  EXPECT_GT(slow->time_constant, limits.max_time_constant);
  EXPECT_GE(slow->force_mid, 8000);
  EXPECT_TRUE(slow_note(*slow));
}

// The same when a thick wire makes the force with two per segment within max_units units: a
// design of up to max_units_resolution fast units still comes first (arm26's SF, 358 N through
// a 0.14 gear: 2550 wires of 0.127 mm, nine per unit at 300 units, three at 1000; 0.51 mm takes
// 159 wires but cools in 13 s).
TEST(Sizing, ManyFastUnitsComeBeforeAThickWireThatMakesTheForceWithFewWires) {
  SizingLimits limits;
  limits.units_per_holding_force = 0;
  SizingInput sf{"SF", 358, 0.2378, 0.1025, 0.3404, 0.3404};
  auto d = SizeBundle(sf, limits);
  ASSERT_TRUE(d.ok()) << d.error();
  EXPECT_LE(d->time_constant, limits.max_time_constant);
  EXPECT_GT(d->units, limits.max_units_fast);
  EXPECT_LE(d->units, limits.max_units_resolution);
  EXPECT_LE(d->unit.parallel, limits.max_parallel);
  EXPECT_GE(d->force_mid, 358);
  for (const std::string& n : d->notes) EXPECT_EQ(n.find("thermal time constant"), n.npos) << n;
}

// The damper rule's closed forms: one joint, two bundles: the joint lands on the ratio exactly
// and the bundles share by stiffness; a joint damped enough takes none; a biarticular bundle
// takes the larger of its joints' shares, so both joints reach at least the ratio.
TEST(Dampers, ClosedFormsOfTheStiffnessProportionalRule) {
  std::vector<DampedJoint> one{{"q", 0.2, 0.05}};
  auto c = DesignDampers(one, {{100, {0.03}}, {50, {-0.02}}}, 0.5);
  ASSERT_TRUE(c.ok()) << c.error();
  const double k = 100 * 0.03 * 0.03 + 50 * 0.02 * 0.02;
  EXPECT_DOUBLE_EQ(one[0].stiffness, k);
  const double need = 2 * 0.5 * std::sqrt(k * 0.2) - 0.05;
  EXPECT_NEAR((*c)[0] * 0.03 * 0.03 + (*c)[1] * 0.02 * 0.02, need, 1e-12);
  EXPECT_NEAR((*c)[0] / (*c)[1], 2.0, 1e-12);
  EXPECT_NEAR(one[0].ratio_after, 0.5, 1e-12);
  EXPECT_NEAR(one[0].ratio_before, 0.05 / (2 * std::sqrt(k * 0.2)), 1e-12);

  std::vector<DampedJoint> damped{{"q", 0.2, 10}};
  c = DesignDampers(damped, {{100, {0.03}}}, 0.5);
  ASSERT_TRUE(c.ok());
  EXPECT_EQ((*c)[0], 0.0);
  EXPECT_EQ(damped[0].damping_after, 10.0);

  std::vector<DampedJoint> two{{"a", 1.0, 0.0}, {"b", 0.1, 0.0}};
  const std::vector<DampedBundle> bundles{
      {200, {0.05, 0.0}}, {80, {0.0, 0.03}}, {60, {0.04, 0.02}}};
  c = DesignDampers(two, bundles, 0.7);
  ASSERT_TRUE(c.ok());
  for (const DampedJoint& j : two) EXPECT_GE(j.ratio_after, 0.7 - 1e-12) << j.joint;
  EXPECT_NEAR(std::min(two[0].ratio_after, two[1].ratio_after), 0.7, 1e-12);
  // The monoarticular bundles carry their own joint's share; the biarticular one the larger.
  const double beta_a = 2 * 0.7 * std::sqrt(two[0].stiffness * 1.0) / two[0].stiffness;
  const double beta_b = 2 * 0.7 * std::sqrt(two[1].stiffness * 0.1) / two[1].stiffness;
  EXPECT_NEAR((*c)[0], beta_a * 200, 1e-9);
  EXPECT_NEAR((*c)[1], beta_b * 80, 1e-9);
  EXPECT_NEAR((*c)[2], std::max(beta_a, beta_b) * 60, 1e-9);

  std::vector<DampedJoint> bad{{"q", 0.0, 0.0}};
  EXPECT_FALSE(DesignDampers(bad, {{1, {0.01}}}, 0.5).ok());
  EXPECT_FALSE(DesignDampers(one, {{1, {0.01}}}, -1).ok());
  EXPECT_FALSE(DesignDampers(one, {{1, {0.01, 0.02}}}, 0.5).ok());
}

// A bundle's stiffness at rest against a finite difference of the plugin's own tension law: the
// units on at mid-range that pull the rest tension, moved by a small tendon length.
TEST(Dampers, RestStiffnessIsTheSlopeOfTheUnitsTension) {
  SizingInput in{"b", 200, 0.06, 0.20, 0.26, 0.22};
  auto d = SizeBundle(in);
  ASSERT_TRUE(d.ok()) << d.error();
  auto u = sma::UnitModel::Create(d->unit);
  ASSERT_TRUE(u.ok());
  const double rest = RestTension(in, SizingLimits{});
  EXPECT_DOUBLE_EQ(rest, 0.05 * 200);
  const double l_mid = 0.23, h = 1e-6;
  auto stretch = [&](double l) { return d->unit.prestretch + d->gear * (l - in.ref_length); };
  const double per_unit = d->gear * u->Tension(0.0, stretch(l_mid));
  const double n = rest / per_unit;  // units on (a real number: the slope is linear in it)
  const double slope = n * d->gear *
                       (u->Tension(0.0, stretch(l_mid + h)) - u->Tension(0.0, stretch(l_mid - h))) /
                       (2 * h);
  EXPECT_NEAR(RestStiffness(*d, in, rest), slope, 1e-6 * slope);
}

TEST(Sizing, MatchesForceWithinLimitsAndCoversTheStroke) {
  for (double force : {5.0, 40.0, 600.0}) {
    for (double excursion : {0.01, 0.03, 0.08}) {
      SizingInput in{"b", force, excursion, 0.2, 0.2 + excursion, 0.2 + 0.4 * excursion};
      auto d = SizeBundle(in);
      ASSERT_TRUE(d.ok()) << d.error();
      const sma::UnitParams& u = d->unit;
      // Force at full recruitment mid-range: at least the request, within 5 %.
      EXPECT_GE(d->force_mid, force);
      EXPECT_LE(d->force_mid, 1.05 * force) << force << " " << excursion;
      // Closed form of a hot segment at the tendon's longest: stretched by eps_L L.
      const double area = 0.25 * M_PI * u.wire_diameter * u.wire_diameter;
      const double k = 1 / (1 / u.series_spring + u.wire_length / (u.E_A * area));
      const double wire_force = k * u.eps_L * u.wire_length;
      EXPECT_NEAR(d->peak_stress, wire_force / area, 1e-6 * d->peak_stress);
      EXPECT_LE(d->peak_stress, 172e6);
      EXPECT_NEAR(d->force_long, d->gear * d->units * u.parallel * wire_force,
                  1e-9 * d->force_long);
      EXPECT_LE(d->steady_temperature, 120);
      EXPECT_LE(u.current, d->max_current);
      // The stroke covers the excursion through the transmission, with the credible length.
      EXPECT_GE(d->stroke + 1e-12, d->gear * excursion / SizingLimits{}.stroke_use);
      EXPECT_LE(u.wire_length * u.series, 1.0 + 1e-9);
      EXPECT_NEAR(d->wire_total, d->units * u.parallel * u.series * u.wire_length, 1e-9);
    }
  }
}

// gear g: extension = prestretch + g (L - L_ref); the tendon gets g x the bundle's tension.
// The sizing stroke rule: at the tendon, a hot unit's force is its stiffness times its stretch,
// which is zero a distance s0 = (1/stroke_use - 1) g E below the tendon's shortest, so the
// relative slope f'/f at the tendon is 1 / (s0 / g + L - L_min): closed form at the shortest.
TEST(Sizing, TheStrokeRuleSetsTheBundlesForceLengthSlope) {
  for (double use : {0.5, 0.85}) {
    SizingLimits limits;
    limits.stroke_use = use;
    SizingInput in{"b", 100, 0.04, 0.2, 0.24, 0.22};
    auto d = SizeBundle(in, limits);
    ASSERT_TRUE(d.ok()) << d.error();
    // Force at the shortest over the longest: s0 / (s0 + g E) = 1 - use.
    EXPECT_NEAR(d->force_short / d->force_long, 1 - use, 1e-9) << use;
  }
}

// Resolution: a bundle gets enough units that one is 1/50 (here) of the force holding its limb's
// weight, by fewer wires per unit (the same wires: the force is unchanged), never past the cap.
TEST(Sizing, ResolutionGivesMoreSmallerUnitsForTheSameForce) {
  SizingInput in{"b", 900, 0.04, 0.1, 0.14, 0.12};
  SizingLimits off;
  off.units_per_holding_force = 0;  // the rule off
  SizingLimits fifty;
  fifty.units_per_holding_force = 50;
  auto coarse = SizeBundle(in, off);
  ASSERT_TRUE(coarse.ok()) << coarse.error();
  in.holding_force = 60;  // 50 units per 60 N: 750 units of 1.2 N
  auto fine = SizeBundle(in, fifty);
  ASSERT_TRUE(fine.ok()) << fine.error();
  const int wires = coarse->units * coarse->unit.parallel;
  const int fine_wires = fine->units * fine->unit.parallel;
  EXPECT_GT(fine->units, coarse->units);
  EXPECT_GE(fine->units, std::min(750, wires));
  // The same wires, up to rounding the last unit up.
  EXPECT_GE(fine_wires, wires);
  EXPECT_LT(fine_wires, wires + fine->unit.parallel);
  EXPECT_NEAR(fine->force_mid / coarse->force_mid, double(fine_wires) / wires, 1e-9);
  EXPECT_THAT(fine->notes, testing::Not(testing::Contains(testing::HasSubstr("resolution"))));
  // The default asks for 150 units in it, 2250 here: one wire per unit, at least as many units
  // as 1/50 gave, and a note that the rule stopped short.
  auto finer = SizeBundle(in);
  ASSERT_TRUE(finer.ok()) << finer.error();
  EXPECT_EQ(SizingLimits{}.units_per_holding_force, 150);
  EXPECT_EQ(finer->unit.parallel, 1);
  EXPECT_GE(finer->units, fine->units);
  EXPECT_LT(finer->units, 2250);
  EXPECT_THAT(finer->notes, testing::Contains(testing::HasSubstr("resolution")));
  // Asking for 45,000 units: the cap (or one wire per unit) stops it, and a note says so.
  in.holding_force = 1;
  auto capped = SizeBundle(in, fifty);
  ASSERT_TRUE(capped.ok()) << capped.error();
  EXPECT_LT(capped->units, 2 * SizingLimits{}.max_units_resolution);
  EXPECT_THAT(capped->notes, testing::Contains(testing::HasSubstr("resolution")));
  // No weight on the bundle (a limb in a horizontal plane): the load is the co-contraction the
  // loop holds, 5 % of the peak force: 50 units in 45 N, i.e. 1000 units wanted (the cap):
  // one wire per unit, as with a 60 N weight.
  in.holding_force = 0;
  auto weightless = SizeBundle(in, fifty);
  ASSERT_TRUE(weightless.ok()) << weightless.error();
  EXPECT_EQ(weightless->unit.parallel, 1);
  EXPECT_EQ(weightless->units, wires);
  EXPECT_GT(weightless->units, coarse->units);
  EXPECT_GE(weightless->force_mid, 900);
}

// The holding load against closed forms: a rod of mass m with its centre l from a hinge,
// swept over -90..90 deg under gravity (largest torque m g l, horizontal), pulled by a fixed
// tendon of moment arm r (force m g l / r); with gravity off, a joint spring k: k x the largest
// distance from its spring reference.
TEST(HoldingLoad, GravityAndSpringsOverTheTendonsArm) {
  const char* xml = R"(<mujoco><option gravity="0 0 -9.81"/>
  <worldbody><body><joint name="h" type="hinge" axis="0 1 0" range="-90 90" stiffness="%g"
      springref="30"/><geom type="sphere" size="0.01" pos="0 0 -0.25" mass="2"/></body></worldbody>
  <tendon><fixed name="t"><joint joint="h" coef="0.02"/></fixed></tendon></mujoco>)";
  for (double k : {0.0, 3.0}) {
    char text[1000];
    std::snprintf(text, sizeof text, xml, k);
    auto m = LoadModelFromString(text);
    ASSERT_TRUE(m.ok()) << m.error();
    if (k > 0) (*m)->opt.gravity[2] = 0;
    DataPtr d(mj_makeData(m->get()));
    const double lo = -M_PI / 2, hi = M_PI / 2;
    const HoldingLoad load = SampleHoldingLoad(m->get(), d.get(), 0, {0}, {lo}, {hi});
    const double torque = k > 0 ? k * (M_PI / 6 - lo) : 2 * 9.81 * 0.25;  // springref 30 deg
    EXPECT_NEAR(load.torque, torque, 1e-9 * torque) << k;
    EXPECT_NEAR(load.arm, 0.02, 1e-12);
    EXPECT_NEAR(load.force(), torque / 0.02, 1e-6 * torque / 0.02);
  }
}

TEST(Gear, IsATransmissionWithTheClosedForm) {
  const char* xml = R"(<mujoco>
  <extension><plugin plugin="recruit.sma"><instance name="u">
    <config key="units" value="10"/></instance></plugin></extension>
  <worldbody><site name="a" pos="0 0 0"/>
    <body pos="0.3 0 0"><joint name="s" type="slide" axis="1 0 0" range="-0.05 0.05"/>
      <geom size="0.01" mass="1"/><site name="b"/></body></worldbody>
  <tendon><spatial name="t"><site site="a"/><site site="b"/></spatial></tendon>
  <actuator><plugin name="p" instance="u" tendon="t" gear="0.5" ctrlrange="-1 1"/></actuator>
</mujoco>)";
  sma::RegisterSmaPlugin();
  sma::testing::WarningCapture quiet;  // the fit check may warn: not into MUJOCO_LOG.TXT
  auto m = LoadModelFromString(xml);
  ASSERT_TRUE(m.ok()) << m.error();
  DataPtr d(mj_makeData(m->get()));
  auto host = sma::SmaHost::Create(m->get());
  ASSERT_TRUE(host.ok()) << host.error();
  const sma::SmaHost& h = **host;
  EXPECT_EQ(h.gear(0), 0.5);
  EXPECT_NEAR(h.ref_length(0), 0.3, 1e-12);  // a tendon length
  h.Reset(d.get(), 1);
  ASSERT_TRUE(h.Broadcast(d.get(), 0, 1, 0).ok());
  for (int i = 0; i < 1000; ++i) mj_step(m->get(), d.get());
  d->qpos[0] = 0.02;
  d->qvel[0] = 0;
  mj_forward(m->get(), d.get());
  const double prestretch = h.bundle(0).config().unit.prestretch;
  EXPECT_NEAR(h.Stretch(d.get(), 0), prestretch + 0.5 * (d->ten_length[0] - 0.3), 1e-12);
  const double tension = h.Force(d.get(), 0);
  EXPECT_GT(tension, 0);
  EXPECT_NEAR(d->actuator_force[0], -tension, 1e-12);
  // Joint force = gear x actuator force x tendon moment (1 on this slide).
  EXPECT_NEAR(d->qfrc_actuator[0], -0.5 * tension, 1e-9);
}

TEST(Gear, NonPositiveGearIsRefused) {
  const char* xml = R"(<mujoco>
  <extension><plugin plugin="recruit.sma"><instance name="u"/></plugin></extension>
  <worldbody><site name="a"/><body pos="0.3 0 0"><joint type="slide" axis="1 0 0"
    range="-0.05 0.05"/><geom size="0.01"/><site name="b"/></body></worldbody>
  <tendon><spatial name="t"><site site="a"/><site site="b"/></spatial></tendon>
  <actuator><plugin name="p" instance="u" tendon="t" gear="-2"/></actuator>
</mujoco>)";
  sma::RegisterSmaPlugin();
  auto m = LoadModelFromString(xml);
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().find("gear=-2 is invalid: must be > 0"), std::string::npos) << m.error();
}

// The starter task of an attached model, read back with the task loader (src/sim/task.cc).
struct AttachedWithTask {
  Result<AttachReport> report = Error{"not run"};
  std::string task;
};

AttachedWithTask AttachArmWithTask(const std::string& name, const std::vector<std::string>& lock) {
  const std::string dir = TempDir(name);
  AttachOptions o;
  o.model = kSrc + "/models/arm2j_muscle.xml";
  o.muscles = {"all"};
  o.output = dir + "/arm2j_sma.xml";
  o.task = dir + "/task.json";
  o.lock = lock;
  return {Attach(o), o.task};
}

std::vector<std::string> DrivenJoints(const sim::Task& t) {
  std::vector<std::string> out;
  for (const sim::DrivenJoint& j : t.joints) out.push_back(j.joint);
  return out;
}

TEST(StarterTask, LockedJointIsNotDriven) {
  using ::testing::ElementsAre;
  auto free = AttachArmWithTask("task_free", {});
  ASSERT_TRUE(free.report.ok()) << free.report.error();
  auto t = sim::Task::FromFile(free.task);
  ASSERT_TRUE(t.ok()) << t.error();
  EXPECT_THAT(DrivenJoints(*t), ElementsAre("shoulder", "elbow"));

  for (const std::string locked : {"elbow", "shoulder"}) {
    auto a = AttachArmWithTask("task_lock_" + locked, {locked});
    ASSERT_TRUE(a.report.ok()) << a.report.error();
    auto tl = sim::Task::FromFile(a.task);
    ASSERT_TRUE(tl.ok()) << tl.error();
    EXPECT_THAT(DrivenJoints(*tl), ElementsAre(locked == "elbow" ? "shoulder" : "elbow"));
    EXPECT_EQ(tl->bundles.size(), 6u);  // every bundle kept
  }
  // A joint the model does not have, and locking everything, are refused; nothing written.
  const std::string dir = TempDir("task_lock_bad");
  AttachOptions o;
  o.model = kSrc + "/models/arm2j_muscle.xml";
  o.muscles = {"all"};
  o.output = dir + "/out.xml";
  o.task = dir + "/task.json";
  o.lock = {"wrist"};
  auto r = Attach(o);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("--lock wrist"), std::string::npos) << r.error();
  o.lock = {"shoulder", "elbow"};
  r = Attach(o);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("drives no joint"), std::string::npos) << r.error();
  EXPECT_TRUE(fs::is_empty(dir));
}

TEST(StarterTask, StepsLieInsideTheUsableRangesAndTheTaskNamesTheNewBundles) {
  auto a = AttachArmWithTask("task_content", {});
  ASSERT_TRUE(a.report.ok()) << a.report.error();
  const AttachReport& r = *a.report;
  auto t = sim::Task::FromFile(a.task);
  ASSERT_TRUE(t.ok()) << t.error();
  EXPECT_EQ(t->tracked, sim::Tracked::kAngle);
  EXPECT_TRUE(t->auto_loop);
  EXPECT_EQ(fs::canonical(t->model_path), fs::canonical(r.output));
  std::vector<std::string> names;
  for (const BundleReport& b : r.bundles) names.push_back(b.name);
  EXPECT_EQ(t->bundles, names);
  ModelPtr m = Load(r.output);
  ASSERT_TRUE(m);
  for (const std::string& n : t->bundles) {
    const int id = mj_name2id(m.get(), mjOBJ_ACTUATOR, n.c_str());
    ASSERT_GE(id, 0) << n;
    EXPECT_GE(m->actuator_plugin[id], 0) << n;
  }

  // The raw file: times strictly increasing, one value per time, in degrees.
  std::ifstream in(a.task);
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j["joints"].size(), t->joints.size());
  for (size_t k = 0; k < t->joints.size(); ++k) {
    const sim::DrivenJoint& dj = t->joints[k];
    const nlohmann::json& ref = j["joints"][k]["reference"];
    ASSERT_EQ(j["joints"][k]["joint"], dj.joint);
    const std::vector<double> times = ref["times"], values = ref["values"];
    ASSERT_EQ(ref["unit"], "deg");
    ASSERT_EQ(times.size(), values.size());
    ASSERT_GE(times.size(), 2u);
    // The usable range: the narrowest over every bundle that crosses the joint (report), and
    // inside the joint's own range in the written model.
    double lo = -INFINITY, hi = INFINITY;
    for (const BundleReport& b : r.bundles) {
      for (const JointUse& u : b.joints) {
        if (u.joint != dj.joint) continue;
        lo = std::max(lo, u.usable_lo);
        hi = std::min(hi, u.usable_hi);
      }
    }
    const int jid = mj_name2id(m.get(), mjOBJ_JOINT, dj.joint.c_str());
    ASSERT_GE(jid, 0);
    ASSERT_TRUE(std::isfinite(lo) && std::isfinite(hi)) << dj.joint;
    EXPECT_GE(lo, m->jnt_range[2 * jid] - 1e-5);
    EXPECT_LE(hi, m->jnt_range[2 * jid + 1] + 1e-5);
    for (size_t i = 0; i < times.size(); ++i) {
      if (i > 0) {
        EXPECT_GT(times[i], times[i - 1]) << dj.joint;
      }
      EXPECT_LT(times[i], t->duration);
      const double q = dj.reference(times[i]);  // rad, as the loader converted it
      EXPECT_NEAR(q, values[i] * M_PI / 180, 1e-12) << dj.joint << " step " << i;
      EXPECT_GT(q, lo) << dj.joint << " step " << i;
      EXPECT_LT(q, hi) << dj.joint << " step " << i;
    }
  }
}

// MyoSuite's models through the installed myo-sim package (a test dependency).
std::string MyoSimDir() {
  FILE* p = popen((kSrc + "/.venv/bin/python -c \"import myo_sim, os; "
                          "print(os.path.dirname(myo_sim.__file__))\" 2>/dev/null")
                      .c_str(),
                  "r");
  if (p == nullptr) return "";
  char buf[512] = "";
  const bool got = fgets(buf, sizeof buf, p) != nullptr;
  pclose(p);
  std::string s = got ? buf : "";
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  return s;
}

TEST(Attach, MyoSuiteElbowAndFingerLoadFromTheirNewFolder) {
  const std::string myo = MyoSimDir();
  if (myo.empty()) GTEST_SKIP() << "myo_sim not installed (pip install myo-sim==0.2.3)";
  for (const char* rel : {"/models/legacy/elbow/myoelbow_1dof6muscles.xml",
                          "/models/legacy/finger/myofinger_v0.xml"}) {
    const std::string dir = TempDir(fs::path(rel).stem().string());
    AttachOptions o;
    o.model = myo + rel;
    o.muscles = {"all"};
    o.output = dir + "/sub/out.xml";
    fs::create_directories(dir + "/sub");
    auto r = Attach(o);
    ASSERT_TRUE(r.ok()) << r.error();
    ModelPtr before = Load(o.model), after = Load(o.output);
    ASSERT_TRUE(before && after);
    EXPECT_EQ(after->nmesh, before->nmesh);
    EXPECT_EQ(after->nbody, before->nbody);
    EXPECT_EQ(after->nu, before->nu);
    for (const BundleReport& b : r->bundles) {
      EXPECT_GE(b.design.force_mid, b.peak_force) << rel << " " << b.name;
      EXPECT_LE(b.design.peak_stress, 172e6);
      const int a = mj_name2id(after.get(), mjOBJ_ACTUATOR, b.name.c_str());
      EXPECT_EQ(after->actuator_trnid[2 * a], b.tendon_id);
    }
    if (std::string(rel).find("elbow") != std::string::npos) {
      EXPECT_EQ(r->bundles.size(), 6u);
    }
  }
}

}  // namespace
}  // namespace recruit::attach

namespace recruit::attach {
namespace {

// Every muscle of `model` attached into an empty temporary folder `name` (model m.xml, starter
// task task.json), the plugin registered.
AttachOptions AllWithTask(const std::string& model, const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  AttachOptions o;
  o.model = model;
  o.muscles = {"all"};
  o.output = (dir / "m.xml").string();
  o.task = (dir / "task.json").string();
  sma::RegisterSmaPlugin();
  return o;
}

// The starter task of an attached two-joint arm runs through the several-joint loop: both
// joints scored, each step named by its joint, the CSV with the second joint's columns.
TEST(StarterTask, RunsThroughTheSeveralJointLoop) {
  const AttachOptions o = AllWithTask(kSrc + "/models/arm2j_muscle.xml", "recruit_attach_run");
  const fs::path dir = fs::path(o.output).parent_path();
  sma::testing::WarningCapture quiet;  // the fit check may warn: not into MUJOCO_LOG.TXT
  auto r = Attach(o);
  ASSERT_TRUE(r.ok()) << r.error();
  auto task = sim::Task::FromFile(o.task);
  ASSERT_TRUE(task.ok()) << task.error();
  ASSERT_EQ(task->joints.size(), 2u);
  sim::RunOptions run;
  run.estimator = "output";  // no identified model needed
  run.duration = 30;         // the first step of each joint, at 20 s
  run.quiet = true;
  const std::string csv = (dir / "steps.csv").string();
  sim::CsvStepWriter writer(csv, 100);
  auto s = sim::RunTask(*task, run, {&writer});
  ASSERT_TRUE(s.ok()) << s.error();
  ASSERT_TRUE(writer.Commit().ok());
  ASSERT_EQ(s->joints.size(), 2u);
  EXPECT_EQ(s->joints[0].joint, "shoulder");
  EXPECT_EQ(s->joints[1].joint, "elbow");
  ASSERT_EQ(s->steps.size(), 2u);  // one step of each joint at 20 s
  ASSERT_EQ(s->step_joints.size(), 2u);
  EXPECT_EQ(s->step_joints[0], "shoulder");
  EXPECT_EQ(s->step_joints[1], "elbow");
  EXPECT_EQ(s->metrics.num_steps, 2);
  EXPECT_NEAR(s->metrics.tracking_rmse,
              std::sqrt(0.5 * (std::pow(s->joints[0].tracking_rmse, 2) +
                               std::pow(s->joints[1].tracking_rmse, 2))),
              1e-12);
  EXPECT_FALSE(s->loop_designs.empty());
  std::ifstream in(csv);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header.rfind("time,reference,measured,angle,elbow.reference,elbow.angle,", 0), 0u)
      << header;
  fs::remove_all(dir);
}

// MyoSuite's two-joint elbow, all six muscles: its shoulder is crossed by the biceps' and
// triceps' long heads alone, which cannot hold the arm raised far. The starter task's steps stay
// where the bundles hold the limb; checked with the run's own holding (sim::HoldJoint on the
// written model through the plant, the units' own tension laws, the task's co-contraction): every
// step pose is held, and the step the whole usable range would have asked (80 % of it) is not.
TEST(StarterTask, StepsWhereTheBundlesHoldTheLimb) {
  const std::string myo = MyoSimDir();
  if (myo.empty()) GTEST_SKIP() << "myo_sim not installed (pip install myo-sim==0.2.3)";
  const AttachOptions o = AllWithTask(myo + "/models/legacy/elbow/myoelbow_2dof6muscles.xml",
                                      "recruit_attach_holdable");
  const fs::path dir = fs::path(o.output).parent_path();
  sma::testing::WarningCapture quiet;
  auto r = Attach(o);
  ASSERT_TRUE(r.ok()) << r.error();
  ASSERT_EQ(r->holdable.size(), 2u);
  EXPECT_TRUE(r->holdable[0].cut()) << r->holdable[0].joint;  // the shoulder
  auto task = sim::Task::FromFile(o.task);
  ASSERT_TRUE(task.ok()) << task.error();
  auto plant = sim::Plant::Create(*task, false);
  ASSERT_TRUE(plant.ok()) << plant.error();
  sim::Plant& p = **plant;
  p.Reset(1);
  std::vector<sim::UnitForce> f;
  for (int i = 0; i < p.num_bundles(); ++i) {
    const int b = p.bundle_index(i);
    const sma::UnitModel* unit = &p.host().bundle(b).unit();
    const double pre = unit->params().prestretch, ref = p.host().unit_ref_length(b);
    f.push_back([unit, pre, ref](double L) { return unit->Tension(0.0, pre + (L - ref)); });
  }
  const int nj = p.num_joints();
  ASSERT_EQ(nj, 2);
  std::vector<std::vector<sim::ReferenceStep>> steps;
  for (int j = 0; j < nj; ++j) steps.push_back(task->joints[j].reference.Steps(task->duration));
  ASSERT_EQ(steps[0].size(), 4u);
  for (std::size_t k = 0; k < steps[0].size(); ++k) {
    Eigen::VectorXd q(nj);
    for (int j = 0; j < nj; ++j) q[j] = steps[j][k].to;
    for (int j = 0; j < nj; ++j) {
      const sim::JointHolding h = sim::HoldJoint(p, j, q, f, task->co_contraction, {});
      EXPECT_TRUE(h.holds()) << "step " << k << " joint " << j << ": " << h.static_torque << " vs "
                             << h.held_torque;
    }
  }
  const HoldableRange& s = r->holdable[0];
  Eigen::VectorXd q(nj);
  q[0] = s.lo + 0.8 * (s.hi - s.lo);
  q[1] = steps[1][3].to;
  EXPECT_FALSE(sim::HoldJoint(p, 0, q, f, task->co_contraction, {}).holds());
  fs::remove_all(dir);
}

}  // namespace
// --lock holds the joint in the written model with a joint equality (MuJoCo's own loader and
// solver keep it at its reference while the bundles pull), and the bundles are sized over the
// joints that still move: the elbow-only tendons then have no excursion, and the biarticular
// flexor's range is its length swept over the shoulder alone (a dense sweep with mj_tendon on
// the original model, the elbow at its reference).
// A muscle kept beside the bundles keeps the lengthrange of the free limb: MuJoCo computing it at
// load with the lock active would make it a fraction of a millimetre wide. Reference: MuJoCo's
// own computation on the original model (the bundles' passive pull moves it a little).
// A limb hanging from a free joint is not held: attach says so for each bundle on it, naming the
// joint; a fixed base says nothing of the kind.
TEST(Attach, ALimbOnAFreeBaseIsNamedInTheWarnings) {
  sma::testing::WarningCapture quiet;  // the fit check may warn: not into MUJOCO_LOG.TXT
  auto said = [](const AttachReport& r, const std::string& bundle) {
    for (const std::string& w : r.warnings) {
      if (w.find("'" + bundle + "': the joints it moves hang from the free joint 'root'") !=
          std::string::npos) {
        return true;
      }
    }
    return false;
  };
  AttachOptions o;
  o.model = kSrc + "/tests/attach/data/floating_arm.xml";
  o.muscles = {"all"};
  o.size_only = true;
  auto floating = Attach(o);
  ASSERT_TRUE(floating.ok()) << floating.error();
  EXPECT_TRUE(said(*floating, "flx"));
  EXPECT_TRUE(said(*floating, "ext"));
  o.model = kSrc + "/tests/attach/data/jump_arm.xml";
  o.muscles = {"flx"};
  auto fixed = Attach(o);
  ASSERT_TRUE(fixed.ok()) << fixed.error();
  for (const std::string& w : fixed->warnings) EXPECT_EQ(w.find("free joint"), std::string::npos);
}

TEST(Lock, KeptMusclesKeepTheFreeLimbsLengthRange) {
  sma::testing::WarningCapture quiet;  // the fit check may warn: not into MUJOCO_LOG.TXT
  const std::string dir = TempDir("lock_kept_muscles");
  AttachOptions o;
  o.model = kSrc + "/models/arm2j_muscle.xml";
  o.muscles = {"EF", "EE"};
  o.output = dir + "/out.xml";
  o.lock = {"shoulder"};
  auto r = Attach(o);
  ASSERT_TRUE(r.ok()) << r.error();
  ModelPtr original = Load(o.model);
  ModelPtr written = Load(o.output);
  ASSERT_TRUE(original && written);
  int kept = 0;
  for (const char* name : {"SF", "SE", "BF", "BE"}) {
    const int a0 = mj_name2id(original.get(), mjOBJ_ACTUATOR, name);
    const int a1 = mj_name2id(written.get(), mjOBJ_ACTUATOR, name);
    ASSERT_GE(a0, 0);
    ASSERT_GE(a1, 0);
    const double lo = original->actuator_lengthrange[2 * a0];
    const double hi = original->actuator_lengthrange[2 * a0 + 1];
    ASSERT_GT(hi - lo, 0.01) << name;  // m: the free limb's
    EXPECT_NEAR(written->actuator_lengthrange[2 * a1], lo, 0.02 * (hi - lo)) << name;
    EXPECT_NEAR(written->actuator_lengthrange[2 * a1 + 1], hi, 0.02 * (hi - lo)) << name;
    ++kept;
  }
  EXPECT_EQ(kept, 4);
  EXPECT_EQ(r->lengthranges_unlocked.size(), 4u);
}

TEST(Lock, HoldsTheJointAndSizesOverTheOthers) {
  auto a = AttachArmWithTask("lock_model", {"elbow"});
  ASSERT_TRUE(a.report.ok()) << a.report.error();
  ModelPtr m = Load(a.report->output);
  ASSERT_TRUE(m);
  ASSERT_EQ(m->neq, 1);
  const int elbow = mj_name2id(m.get(), mjOBJ_JOINT, "elbow");
  EXPECT_EQ(m->eq_type[0], mjEQ_JOINT);
  EXPECT_EQ(m->eq_obj1id[0], elbow);
  EXPECT_EQ(m->eq_obj2id[0], -1);
  DataPtr d(mj_makeData(m.get()));
  for (int i = 0; i < m->nu; ++i) d->ctrl[i] = 0;
  double worst = 0;
  for (int k = 0; k < 500; ++k) {  // 1 s: the limb falls under gravity onto its bundles
    mj_step(m.get(), d.get());
    worst = std::max(worst, std::abs(d->qpos[m->jnt_qposadr[elbow]] - m->qpos0[elbow]));
  }
  EXPECT_LT(worst, 0.02);  // rad: held (a soft constraint)

  ModelPtr plain = LoadPlain(kSrc + "/models/arm2j_muscle.xml");
  ASSERT_TRUE(plain);
  DataPtr pd(mj_makeData(plain.get()));
  const int shoulder = mj_name2id(plain.get(), mjOBJ_JOINT, "shoulder");
  for (const BundleReport& b : a.report->bundles) {
    bool crosses_shoulder = false;
    for (const JointUse& j : b.joints) {
      EXPECT_NE(j.joint, "elbow") << b.name;
      crosses_shoulder = crosses_shoulder || j.joint == "shoulder";
    }
    double lo = INFINITY, hi = -INFINITY;
    for (int i = 0; i <= 2000; ++i) {
      mju_copy(pd->qpos, plain->qpos0, plain->nq);
      pd->qpos[plain->jnt_qposadr[shoulder]] =
          plain->jnt_range[2 * shoulder] +
          i / 2000.0 * (plain->jnt_range[2 * shoulder + 1] - plain->jnt_range[2 * shoulder]);
      mj_kinematics(plain.get(), pd.get());
      mj_comPos(plain.get(), pd.get());
      mj_tendon(plain.get(), pd.get());
      const double l = pd->ten_length[b.tendon_id];
      lo = std::min(lo, l), hi = std::max(hi, l);
    }
    if (crosses_shoulder) {
      EXPECT_NEAR(b.length_min, lo, 1e-5) << b.name;
      EXPECT_NEAR(b.length_max, hi, 1e-5) << b.name;
    } else {
      EXPECT_EQ(b.length_max - b.length_min, 0.0) << b.name;  // EF, EE: only the elbow moved them
      EXPECT_LT(hi - lo, 1e-9) << b.name;
    }
  }
}

// A held joint does not move a tendon: the sweep leaves it out and holds it where the
// equality holds it (0.3 rad from its reference here), against the closed form of a two-link
// arm with a straight tendon from a fixed site.
TEST(TendonRange, AJointAnEqualityHoldsIsLeftOut) {
  const char* xml = R"(<mujoco><worldbody>
  <site name="s0" pos="-0.1 0 0"/>
  <body><joint name="a" type="hinge" axis="0 1 0" range="-60 60"/>
    <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.01"/>
    <body pos="0.3 0 0"><joint name="b" type="hinge" axis="0 1 0" range="-60 60"/>
      <geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.01"/>
      <site name="s1" pos="0.2 0 0"/></body></body></worldbody>
  <tendon><spatial name="t"><site site="s0"/><site site="s1"/></spatial></tendon>
  %s</mujoco>)";
  auto build = [&](const std::string& eq) {
    char buf[2000];
    std::snprintf(buf, sizeof buf, xml, eq.c_str());
    char error[500] = "";
    mjSpec* s = mj_parseXMLString(buf, nullptr, error, sizeof error);
    EXPECT_NE(s, nullptr) << error;
    ModelPtr m(mj_compile(s, nullptr));
    mj_deleteSpec(s);
    return m;
  };
  ModelPtr free = build("");
  ModelPtr held = build(R"(<equality><joint joint1="b" polycoef="0.3 0 0 0 0"/></equality>)");
  ASSERT_TRUE(free && held);
  DataPtr d(mj_makeData(held.get()));
  const sma::TendonRange both = sma::SampleTendonRange(free.get(), d.get(), 0);
  EXPECT_EQ(both.joints.size(), 2u);
  const sma::TendonRange one = sma::SampleTendonRange(held.get(), d.get(), 0);
  ASSERT_EQ(one.joints.size(), 1u);
  EXPECT_EQ(one.joints[0], 0);
  // Closed form: with b at 0.3 the tip is R(x) v from a's axis, v = (0.3 + 0.2 cos 0.3,
  // 0.2 sin 0.3), and s0 is c = 0.1 behind it: l^2 = |v|^2 + 0.01 + 0.2 |v| cos(x + phi), phi the
  // angle of v, x over +-60 deg: longest at x = -phi, shortest at the end 60 deg from it.
  const double vx = 0.3 + 0.2 * std::cos(0.3), vy = 0.2 * std::sin(0.3);
  const double v = std::hypot(vx, vy), phi = std::atan2(vy, vx);
  EXPECT_NEAR(one.length_max, std::sqrt(v * v + 0.01 + 0.2 * v), 1e-7);
  EXPECT_NEAR(one.length_min, std::sqrt(v * v + 0.01 + 0.2 * v * std::cos(M_PI / 3 + phi)), 1e-7);
}

// Resolution past one wire per unit: thinner stock wire, more units of it, the same force (the
// bundle still meets the peak force to within one unit), and faster units.
TEST(Sizing, ResolutionTakesThinnerWireWhenOneWirePerUnitIsNotEnough) {
  SizingInput in{"b", 40, 0.03, 0.1, 0.13, 0.115};
  SizingLimits off;
  off.units_per_holding_force = 0;  // the rule off
  auto coarse = SizeBundle(in, off);
  ASSERT_TRUE(coarse.ok()) << coarse.error();
  in.holding_force = 4;  // 50 units per 4 N: 500 units wanted, more than its wires
  ASSERT_LT(coarse->units * coarse->unit.parallel, 500);
  SizingLimits fifty;
  fifty.units_per_holding_force = 50;
  auto fine = SizeBundle(in, fifty);
  ASSERT_TRUE(fine.ok()) << fine.error();
  EXPECT_LT(fine->unit.wire_diameter, coarse->unit.wire_diameter);
  EXPECT_GT(fine->units, coarse->units);
  EXPECT_EQ(fine->unit.parallel, 1);
  EXPECT_LE(fine->units, SizingLimits{}.max_units_resolution);
  EXPECT_GE(fine->force_mid, in.peak_force);
  EXPECT_LT(fine->force_mid, in.peak_force * (1 + 1.0 / fine->units) + 1e-9);
  EXPECT_LT(fine->time_constant, coarse->time_constant);
}

}  // namespace recruit::attach
