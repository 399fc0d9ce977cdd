// How bundles hold a pose (sim/holding.h), checked against finite differences of the plant's
// own tendon lengths and moment arms, and of the torque the held counts give.
#include "sim/holding.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "sim/plant.h"
#include "sim/task.h"
#include "tests/plugin/mujoco_util.h"

namespace recruit::sim {
namespace file_holding_test {

const std::string kRoot = RECRUIT_SOURCE_DIR;
namespace fs = std::filesystem;

// A lever pulled up and down by two bundles on straight tendons from fixed points: their moment
// arms change with the angle (the elbow arm's pulley keeps them constant).
constexpr char kLever[] = R"(<mujoco model="lever">
  <option timestep="0.002" gravity="0 0 -9.81"/>
  <extension><plugin plugin="recruit.sma">
    <instance name="up_units"><config key="units" value="40"/><config key="series" value="4"/>
      <config key="parallel" value="2"/><config key="prestretch" value="0.012"/></instance>
    <instance name="down_units"><config key="units" value="40"/><config key="series" value="4"/>
      <config key="parallel" value="2"/><config key="prestretch" value="0.012"/></instance>
  </plugin></extension>
  <worldbody>
    <site name="top" pos="0.05 0 0.08"/><site name="bottom" pos="0.05 0 -0.08"/>
    <body name="link">
      <joint name="elbow" type="hinge" axis="0 1 0" range="-1 1" damping="0.05"/>
      <geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.01" mass="0.2"/>
      <site name="tip" pos="0.15 0 0"/>
    </body>
  </worldbody>
  <tendon>
    <spatial name="up_t"><site site="top"/><site site="tip"/></spatial>
    <spatial name="down_t"><site site="bottom"/><site site="tip"/></spatial>
  </tendon>
  <actuator>
    <plugin name="flexor" plugin="recruit.sma" instance="up_units" tendon="up_t"/>
    <plugin name="extensor" plugin="recruit.sma" instance="down_units" tendon="down_t"/>
  </actuator>
</mujoco>)";

std::string LeverModel() {
  const fs::path dir = fs::temp_directory_path() / "recruit_holding_test";
  fs::create_directories(dir);
  std::ofstream(dir / "lever.xml") << kLever;
  return (dir / "lever.xml").string();
}

// The plant of a one-joint angle task on `model` (joint "elbow", bundles "flexor", "extensor").
std::unique_ptr<Plant> OneJointPlant(const std::string& model, double co_contraction) {
  const std::string text = R"({"name": "t", "model": ")" + model + R"(", "tracked": "angle",
    "joints": [{"joint": "elbow", "reference": {"type": "constant", "value": 20, "unit": "deg"}}],
    "bundles": ["flexor", "extensor"], "co_contraction": )" +
                           std::to_string(co_contraction) + R"(, "duration": 10,
    "controller": {"estimator": "output", "dT": 1.0}, "outer_loop": "auto"})";
  auto task = Task::FromJsonText(text, kRoot + "/models/tasks/t.json");
  EXPECT_TRUE(task.ok()) << task.error();
  static std::vector<std::unique_ptr<Task>> keep;  // a plant keeps a pointer to its task
  keep.push_back(std::make_unique<Task>(*task));
  sma::testing::WarningCapture quiet;  // the lever's bundles are not fitted to its tendons
  auto plant = Plant::Create(*keep.back(), false);
  EXPECT_TRUE(plant.ok()) << plant.error();
  (*plant)->Reset(1);
  return std::move(plant).value();
}

struct Case {
  std::unique_ptr<Plant> plant;
  std::vector<double> deg;  // poses where both bundles are taut
};

std::vector<Case> Cases() {
  std::vector<Case> out;
  out.push_back({OneJointPlant(kRoot + "/models/elbow_arm.xml", 0.05), {15, 40, 65}});
  out.push_back({OneJointPlant(LeverModel(), 0.05), {-4, 0, 4}});
  return out;
}

// Each bundle's unit force map from its units' physics: a unit fully transformed at the
// extension the length gives.
std::vector<UnitForce> PhysicsUnitForces(const Plant& plant) {
  std::vector<UnitForce> out;
  for (int i = 0; i < plant.num_bundles(); ++i) {
    const int b = plant.bundle_index(i);
    const sma::UnitModel* unit = &plant.host().bundle(b).unit();
    const double prestretch = unit->params().prestretch;
    const double ref = plant.host().unit_ref_length(b);
    out.push_back([unit, prestretch, ref](double L) {
      return std::max(0.0, unit->Tension(0.0, prestretch + (L - ref)));
    });
  }
  return out;
}

Eigen::VectorXd At(double deg) { return Eigen::VectorXd::Constant(1, deg * M_PI / 180); }

// A bundle pulls its tendon shorter: the length coordinate falls at the rate of the torque per
// newton (the relation the stiffness's force-length term rests on).
TEST(Holding, LengthFallsAsTheTorquePerNewton) {
  for (const Case& c : Cases()) {
    const auto& plant = c.plant;
    for (double deg : c.deg) {
      const double h = 1e-6;
      const Eigen::VectorXd dl = (plant->UnitLengthsAt(At(deg) + Eigen::VectorXd::Constant(1, h)) -
                                  plant->UnitLengthsAt(At(deg) - Eigen::VectorXd::Constant(1, h))) /
                                 (2 * h);
      const Eigen::MatrixXd arms = plant->MomentArmsAt(At(deg));
      for (int i = 0; i < plant->num_bundles(); ++i) {
        EXPECT_NEAR(dl[i], -arms(0, i), 1e-6 * std::abs(arms(0, i)) + 1e-9) << deg << " " << i;
      }
    }
  }
}

// The stiffness per newton (coef) against the torque of counts held at the pose's, differenced
// at a step ten times finer than the one the code uses; and the held tensions meet the pose's
// static torque.
TEST(Holding, StiffnessIsMinusTheTorqueSlopeAtHeldCounts) {
  double geometric = 0;  // the largest change of a moment arm seen, N m/N per rad
  for (const Case& c : Cases()) {
    const auto& plant = c.plant;
    const std::vector<UnitForce> f = PhysicsUnitForces(*plant);
    std::mt19937 gen(5);
    std::uniform_real_distribution<double> tension(1, 30);
    for (double deg : c.deg) {
      const Eigen::VectorXd r = At(deg);
      const JointHolding hold = HoldJoint(*plant, 0, r, f, 0.05, Eigen::VectorXd());
      const Eigen::VectorXd l0 = plant->UnitLengthsAt(r);
      Eigen::VectorXd t(plant->num_bundles());
      for (int i = 0; i < t.size(); ++i) t[i] = tension(gen);
      auto torque = [&](double dq) {
        const Eigen::VectorXd q = r + Eigen::VectorXd::Constant(1, dq);
        const Eigen::MatrixXd a = plant->MomentArmsAt(q);
        const Eigen::VectorXd l = plant->UnitLengthsAt(q);
        double tau = 0;
        for (int i = 0; i < t.size(); ++i) tau += a(0, i) * t[i] / f[i](l0[i]) * f[i](l[i]);
        return tau;
      };
      const double h = 1e-4;
      const double slope = -(torque(h) - torque(-h)) / (2 * h);
      EXPECT_NEAR(hold.coef.dot(t), slope, 2e-3 * std::abs(slope) + 1e-6) << deg;
      const double static_torque = plant->StaticTorque(r)[0];
      EXPECT_NEAR((plant->MomentArmsAt(r) * hold.tensions)[0], static_torque,
                  1e-3 * std::abs(static_torque) + 1e-6)
          << deg;
      const Eigen::MatrixXd da =
          (plant->MomentArmsAt(At(deg + 1)) - plant->MomentArmsAt(At(deg - 1))) / (2 * M_PI / 180);
      geometric = std::max(geometric, da.cwiseAbs().maxCoeff());
    }
  }
  // The lever's arms change: the moment-arm term of the stiffness was exercised.
  EXPECT_GT(geometric, 0.01);
}

// A pose is held when the bundles can meet its static torque: with the units' own forces every
// pose is; with every unit's force scaled down until all the units of the bundle that helps
// give less than the static torque, none is, and the torque they reach is that bundle's every
// unit on (its capacity times its arm) less the antagonist's co-contraction floor.
TEST(Holding, APoseBeyondTheBundlesIsNotHeld) {
  int tested = 0;
  for (const Case& c : Cases()) {
    const auto& plant = c.plant;
    const std::vector<UnitForce> f = PhysicsUnitForces(*plant);
    for (double deg : c.deg) {
      const Eigen::VectorXd r = At(deg);
      const JointHolding hold = HoldJoint(*plant, 0, r, f, 0.05, Eigen::VectorXd());
      EXPECT_TRUE(hold.holds()) << deg;
      EXPECT_DOUBLE_EQ(hold.static_torque, plant->StaticTorque(r)[0]);
      // Scaled so that the helping bundle's capacity is half the static torque.
      const Eigen::MatrixXd arms = plant->MomentArmsAt(r);
      const Eigen::VectorXd lengths = plant->UnitLengthsAt(r);
      const double tau = hold.static_torque;
      if (std::abs(tau) < 1e-6) continue;
      int helper = -1;
      for (int i = 0; i < plant->num_bundles(); ++i) {
        if (arms(0, i) * tau > 0) helper = i;
      }
      ASSERT_GE(helper, 0);
      const double cap = plant->num_units(helper) * f[helper](lengths[helper]);
      const double scale = 0.5 * std::abs(tau) / (cap * std::abs(arms(0, helper)));
      std::vector<UnitForce> weak;
      for (const UnitForce& g : f) weak.push_back([g, scale](double L) { return scale * g(L); });
      const JointHolding short_of = HoldJoint(*plant, 0, r, weak, 0.05, Eigen::VectorXd());
      EXPECT_FALSE(short_of.holds()) << deg;
      double reach = 0;
      for (int i = 0; i < plant->num_bundles(); ++i) {
        const double cap_i = plant->num_units(i) * weak[i](lengths[i]);
        reach += arms(0, i) * (i == helper ? cap_i : 0.05 * cap_i);
      }
      EXPECT_NEAR(short_of.held_torque, reach, 1e-6 * std::abs(tau)) << deg;
      ++tested;
    }
  }
  EXPECT_GE(tested, 4);  // poses with a static torque on both limbs
}

}  // namespace file_holding_test
}  // namespace recruit::sim
