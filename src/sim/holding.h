// How a limb's bundles hold a driven joint at a pose: the tensions that meet the pose's static
// torque (shared as the self-tuned loop shares a demand, with co-contraction where the joint
// would otherwise be held with too little stiffness) and the joint's stiffness at constant
// on-counts. docs/controller.md, "Holding a pose".
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <functional>
#include <vector>

#include "control/torque_allocation.h"
#include "sim/plant.h"

namespace recruit::sim {

// Tension (N) of one unit that is on, at bundle length coordinate L (Plant::UnitLength).
using UnitForce = std::function<double(double L)>;

struct JointHolding {
  double stiffness = 0;  // N m/rad: the bundles' at constant on-counts
  double torque = 0;     // N m: the sum of the bundles' torques' magnitudes
  // Per bundle, N m/rad per newton: its stiffness on the joint per unit of its tension.
  Eigen::VectorXd coef;
  double limb_stiffness = 0;  // N m/rad: d tau_static / dq, the limb's own
  Eigen::VectorXd tensions;   // N, per bundle: what holds the pose
  double static_torque = 0;   // N m: the pose's static torque on the joint (what holds it)
  // N m: the bundles' torque on the joint with `tensions`; short of static_torque (beyond
  // held_tolerance) when the pose asks more than the bundles can give, every unit on.
  double held_torque = 0;
  double held_tolerance = 0;  // N m: 1e-3 of the joint's torque span, sum_i |A_ji| cap_i
  bool holds() const { return std::abs(static_torque - held_torque) <= held_tolerance; }
  double total() const { return limb_stiffness + stiffness; }
};

// The allocation (control::AllocateTensions) with, for each joint that has a holding and would
// be held with less stiffness than kStiffnessMargin of the magnitudes it is made of, one more row
// that asks for that much.
Eigen::VectorXd AllocateHolding(const control::AllocationProblem& p,
                                const std::vector<const JointHolding*>& holding);

// Joint j held at pose r (the driven joints' angles) by the plant's bundles with unit force maps
// `on_unit_force` (in the plant's bundle order), least tensions co_contraction x capacity and
// the allocation's prices `price` (empty: all 1).
JointHolding HoldJoint(const Plant& plant, int j, const Eigen::VectorXd& r,
                       const std::vector<UnitForce>& on_unit_force, double co_contraction,
                       const Eigen::VectorXd& price);

}  // namespace recruit::sim
