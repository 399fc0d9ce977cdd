#include "sim/holding.h"

#include <algorithm>
#include <cmath>

#include "sim/loop_constants.h"

namespace recruit::sim {
namespace {

constexpr double kStiffnessStep = 1e-3;  // rad, for d tau_static / dq and d arms / dq
constexpr double kLengthStep = 1e-4;     // m, for a unit force map's slope

}  // namespace

Eigen::VectorXd AllocateHolding(const control::AllocationProblem& p,
                                const std::vector<const JointHolding*>& holding) {
  const Eigen::VectorXd t = control::AllocateTensions(p);
  control::AllocationProblem q = p;
  int added = 0;
  for (const JointHolding* h : holding) {
    if (h == nullptr) continue;
    const double least =
        kStiffnessMargin * (std::abs(h->limb_stiffness) + h->coef.cwiseAbs().dot(t));
    if (h->limb_stiffness + h->coef.dot(t) >= least) continue;
    q.arms.conservativeResize(q.arms.rows() + 1, Eigen::NoChange);
    q.torque.conservativeResize(q.torque.size() + 1);
    q.arms.row(q.arms.rows() - 1) = h->coef.transpose();
    q.torque[q.torque.size() - 1] = least - h->limb_stiffness;
    ++added;
  }
  return added ? control::AllocateTensions(q) : t;
}

JointHolding HoldJoint(const Plant& plant, int j, const Eigen::VectorXd& r,
                       const std::vector<UnitForce>& on_unit_force, double co_contraction,
                       const Eigen::VectorXd& price) {
  const int nb = plant.num_bundles();
  const Eigen::MatrixXd arms = plant.MomentArmsAt(r);
  const Eigen::VectorXd lengths = plant.UnitLengthsAt(r);
  Eigen::VectorXd up = r, down = r;
  up[j] += kStiffnessStep;
  down[j] -= kStiffnessStep;
  const Eigen::VectorXd arm_slope =
      (plant.MomentArmsAt(up).row(j) - plant.MomentArmsAt(down).row(j)).transpose() /
      (2 * kStiffnessStep);
  control::AllocationProblem p;
  p.arms = arms;
  p.torque = plant.StaticTorque(r);
  p.cap.resize(nb);
  p.floor.resize(nb);
  p.price = price;
  Eigen::VectorXd slope(nb);  // d ln(unit force) / dL, 1/m
  for (int i = 0; i < nb; ++i) {
    const double f = on_unit_force[i](lengths[i]);
    p.cap[i] = std::max(plant.num_units(i) * f, 1e-9);
    p.floor[i] = co_contraction * p.cap[i];
    slope[i] = f > 0 ? (on_unit_force[i](lengths[i] + kLengthStep) -
                        on_unit_force[i](lengths[i] - kLengthStep)) /
                           (2 * kLengthStep * f)
                     : 0.0;
  }
  // Torque tau_j = sum_i A_ji T_i with T_i = n_i f_i(L_i) and dL_i/dq_j = -A_ji (a bundle shortens
  // as it pulls): at constant counts -dtau_j/dq_j = sum_i T_i (A_ji^2 f_i'/f_i - dA_ji/dq_j).
  JointHolding h;
  h.coef.resize(nb);
  for (int i = 0; i < nb; ++i) h.coef[i] = arms(j, i) * arms(j, i) * slope[i] - arm_slope[i];
  h.limb_stiffness =
      (plant.StaticTorque(up)[j] - plant.StaticTorque(down)[j]) / (2 * kStiffnessStep);
  std::vector<const JointHolding*> rows(plant.num_joints(), nullptr);
  rows[j] = &h;
  h.tensions = AllocateHolding(p, rows);
  h.stiffness = h.coef.dot(h.tensions);
  for (int i = 0; i < nb; ++i) h.torque += std::abs(arms(j, i) * h.tensions[i]);
  h.static_torque = p.torque[j];
  h.held_torque = arms.row(j).dot(h.tensions);
  h.held_tolerance = 1e-3 * arms.row(j).cwiseAbs().dot(p.cap);
  return h;
}

}  // namespace recruit::sim
