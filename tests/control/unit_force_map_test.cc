// UnitForceMap, the length-dependent output model: against the forces the plugin itself gives
// with the elbow arm held at fixed angles (an independent reference: the plugin integrates each
// unit's thermal and phase state, the map only evaluates the force law at one fraction per state),
// and its inverse against its forward map.
#include "control/unit_force_map.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>

#include "common/mujoco_ptr.h"
#include "plugin/sma_host.h"

namespace recruit::control {
namespace file_unit_force_map_test {

constexpr double kDeg = M_PI / 180.0;

// The elbow arm with its joint held at an angle (qpos set, qvel zeroed before every step).
class HeldArm {
 public:
  HeldArm() {
    char err[1000] = "";
    m_.reset(mj_loadXML(RECRUIT_SOURCE_DIR "/models/elbow_arm.xml", nullptr, err, sizeof err));
    EXPECT_TRUE(m_) << err;
    auto host = sma::SmaHost::Create(m_.get());
    EXPECT_TRUE(host.ok()) << host.error();
    host_ = std::move(host).value();
    d_.reset(mj_makeData(m_.get()));
    host_->Reset(d_.get(), 7);
    qadr_ = m_->jnt_qposadr[mj_name2id(m_.get(), mjOBJ_JOINT, "elbow")];
    flexor_ = host_->BundleIndex("flexor");
  }
  // Holds the angle for `seconds`.
  void Hold(double angle, double seconds) {
    const int steps = static_cast<int>(std::lround(seconds / m_->opt.timestep));
    for (int i = 0; i < steps; ++i) {
      d_->qpos[qadr_] = angle;
      for (int k = 0; k < m_->nv; ++k) d_->qvel[k] = 0;
      mj_step(m_.get(), d_.get());
    }
    d_->qpos[qadr_] = angle;
    mj_forward(m_.get(), d_.get());
  }
  const sma::SmaHost& host() const { return *host_; }
  mjData* data() { return d_.get(); }
  int flexor() const { return flexor_; }
  double length() const { return d_->ten_length[host_->tendon_id(flexor_)]; }
  UnitGeometry geometry() const {
    return {host_->bundle(flexor_).config().unit, host_->ref_length(flexor_)};
  }
  double ForcePerUnit() const {
    return host_->Force(d_.get(), flexor_) / host_->num_units(flexor_);
  }

 private:
  ModelPtr m_;
  std::unique_ptr<sma::SmaHost> host_;
  DataPtr d_;
  int qadr_ = 0, flexor_ = -1;
};

// The settled on unit's force from the plugin's SettledUnitForce at the reference length, carried
// to other lengths by the map, against the plugin's force with every unit heated and settled at
// that angle: within 2 % over the arm's range (a fixed H is off by up to 35 %).
TEST(UnitForceMap, SettledOnForceFollowsTheTendonLengthLikeThePlugin) {
  for (double deg : {0.0, 20.0, 40.0, 60.0, 80.0}) {
    HeldArm arm;
    const sma::SmaHost& h = arm.host();
    auto map =
        UnitForceMap::FromForces(arm.geometry(), arm.geometry().unit.prestretch,
                                 Eigen::VectorXd::Constant(1, h.SettledUnitForce(arm.flexor())));
    ASSERT_TRUE(map.ok()) << map.error();
    arm.Hold(deg * kDeg, 0.1);
    ASSERT_TRUE(h.Broadcast(arm.data(), arm.flexor(), 1.0, 0.0).ok());
    arm.Hold(deg * kDeg, 10.0);
    const double plugin = arm.ForcePerUnit();
    const double predicted = map->Force(0, arm.length());
    SCOPED_TRACE(deg);
    EXPECT_GT(plugin, 0.2);  // a hot unit pulls 0.45 N at 0 deg, 0.24 N at 80 deg
    EXPECT_NEAR(predicted, plugin, 0.02 * plugin);
  }
}

// Hysteresis: units heated at 60 deg and then extended to 10 deg keep their fraction, so their
// force follows the force law at that fraction (the plugin's), not the force of units heated at
// 10 deg or a constant.
TEST(UnitForceMap, UnitsMovedAfterHeatingFollowTheForceLawAtTheirFraction) {
  HeldArm arm;
  const sma::SmaHost& h = arm.host();
  arm.Hold(60 * kDeg, 0.1);
  ASSERT_TRUE(h.Broadcast(arm.data(), arm.flexor(), 1.0, 0.0).ok());
  arm.Hold(60 * kDeg, 10.0);
  const double xi = h.MeanXi(arm.data(), arm.flexor());
  auto map = UnitForceMap::FromFractions(arm.geometry(), Eigen::VectorXd::Constant(1, xi));
  ASSERT_TRUE(map.ok()) << map.error();
  arm.Hold(10 * kDeg, 0.5);
  const double plugin = arm.ForcePerUnit();
  EXPECT_NEAR(map->Force(0, arm.length()), plugin, 0.02 * plugin);
}

// The inverse: fractions -> forces at an extension -> fractions gives the fractions back wherever
// the unit is taut there; every force is >= 0 at every length, and grows with the length.
TEST(UnitForceMap, FromForcesInvertsTheForceLawWhereTaut) {
  UnitGeometry g;
  g.ref_length = 0.2;
  Eigen::VectorXd xi(6);
  xi << 0.0, 0.1, 0.3, 0.55, 0.8, 0.95;
  auto map = UnitForceMap::FromFractions(g, xi);
  ASSERT_TRUE(map.ok()) << map.error();
  const double s = map->unit().recoverable_stretch();  // every state with xi < 1 is taut
  Eigen::VectorXd f(6);
  for (int i = 0; i < 6; ++i) f[i] = map->unit().Tension(xi[i], s);
  auto back = UnitForceMap::FromForces(g, s, f);
  ASSERT_TRUE(back.ok()) << back.error();
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(back->fractions()[i], xi[i], 1e-12) << i;
  Eigen::RowVectorXd h_short(6), h_long(6);
  for (double dL = -0.004; dL <= 0.004; dL += 0.001) {
    map->Forces(g.ref_length + dL, h_short);
    map->Forces(g.ref_length + dL + 1e-4, h_long);
    EXPECT_TRUE((h_short.array() >= 0).all());
    EXPECT_TRUE((h_long.array() >= h_short.array()).all());
  }
  // A force no fraction reaches at that extension clamps to austenite; none at all to martensite.
  auto clamped = UnitForceMap::FromForces(g, s, Eigen::Vector2d(1e3, -1.0));
  ASSERT_TRUE(clamped.ok());
  EXPECT_EQ(clamped->fractions()[0], 0.0);
  EXPECT_EQ(clamped->fractions()[1], 1.0);
  EXPECT_FALSE(UnitForceMap::FromFractions(g, Eigen::Vector2d(0.5, 1.5)).ok());
}

}  // namespace file_unit_force_map_test
}  // namespace recruit::control
