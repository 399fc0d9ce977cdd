#include "sim/joint_loop.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "control/torque_allocation.h"

namespace recruit::sim {
namespace {

constexpr double kStiffnessStep = 1e-3;  // rad, for d tau_static / dq
constexpr double kLimitMargin = 0.03;    // of a joint's range: the loop's reference stays inside

}  // namespace

double ShortestHold(const Reference& reference, double duration) {
  double shortest = duration;
  for (const ReferenceStep& s : reference.Steps(duration)) {
    shortest = std::min(shortest, s.end - s.time);
  }
  return shortest;
}

Eigen::VectorXd JointLoops::LoopReference(const Plant& plant, double t) const {
  Eigen::VectorXd r(plant.num_joints());
  for (int j = 0; j < plant.num_joints(); ++j) {
    r[j] = task_->joints[j].reference(t);
    // Not into a limit: a reference at the end of the range would have the bundles press the
    // limb against it (and the loop's integral wind up there).
    double lo, hi;
    if (plant.JointRange(j, &lo, &hi)) {
      const double margin = kLimitMargin * (hi - lo);
      r[j] = std::clamp(r[j], lo + margin, hi - margin);
    }
  }
  return r;
}

Result<JointLoops> JointLoops::Create(const Task& task, const Plant& plant,
                                      std::vector<control::ActuatorResponse> responses, double dT) {
  if (static_cast<int>(responses.size()) != plant.num_bundles()) {
    return Error{"joint loops: one actuator response per bundle is needed"};
  }
  JointLoops loops;
  loops.task_ = &task;
  loops.responses_ = std::move(responses);
  loops.dT_ = dT;
  loops.target_.band = task.settle_band;
  // The hold a step has to settle in: the shortest of the task's steps, at most 60 s (a longer
  // hold would only allow a slower design).
  double hold = 60;
  for (const DrivenJoint& d : task.joints) {
    hold = std::min(hold, ShortestHold(d.reference, task.duration));
  }
  loops.target_.hold = std::max(hold, 4 * dT);
  loops.gains_.resize(plant.num_joints());
  loops.integral_.assign(plant.num_joints(), 0.0);
  // Slower bundles are priced by how much slower they are than the fastest: the fast ones take
  // a joint's demand where they can, the slow ones what only they can give.
  double fastest = std::numeric_limits<double>::infinity();
  for (const control::ActuatorResponse& r : loops.responses_) {
    fastest = std::min(fastest, r.TimeTo(0.63));
  }
  loops.price_.resize(plant.num_bundles());
  for (int i = 0; i < plant.num_bundles(); ++i) {
    loops.price_[i] = loops.responses_[i].TimeTo(0.63) / fastest;
  }
  return loops;
}

Result<JointDesignRecord> JointLoops::Design(const Plant& plant, int j,
                                             const Eigen::VectorXd& r) const {
  JointDesignRecord rec;
  rec.joint = plant.joint_name(j);
  rec.reference = r[j];
  Eigen::VectorXd up = r, down = r;
  up[j] += kStiffnessStep;
  down[j] -= kStiffnessStep;
  rec.dynamics.stiffness =
      (plant.StaticTorque(up)[j] - plant.StaticTorque(down)[j]) / (2 * kStiffnessStep);
  rec.dynamics.inertia = plant.JointInertia(j, r);
  rec.dynamics.damping = plant.JointDamping(j);
  // The response of the joint's torque: the allocation gives a demand to the fastest bundles
  // that can meet it, so the slower of the fastest bundle on each side sets it.
  const Eigen::MatrixXd arms = plant.MomentArms();
  const control::ActuatorResponse* side[2] = {nullptr, nullptr};  // flexing, extending
  for (int i = 0; i < plant.num_bundles(); ++i) {
    if (arms(j, i) == 0) continue;
    const control::ActuatorResponse*& s = side[arms(j, i) > 0 ? 0 : 1];
    if (s == nullptr || responses_[i].TimeTo(0.63) < s->TimeTo(0.63)) s = &responses_[i];
  }
  const control::ActuatorResponse* act = side[0];
  if (act == nullptr || (side[1] != nullptr && side[1]->TimeTo(0.63) > act->TimeTo(0.63))) {
    act = side[1];
  }
  if (act == nullptr) return Error{"joint '" + rec.joint + "': no bundle of the task crosses it"};
  rec.actuator_t63 = act->TimeTo(0.63);
  auto d = control::DesignJointLoop(rec.dynamics, *act, dT_, target_);
  if (!d.ok()) return Error{"joint '" + rec.joint + "': " + d.error()};
  rec.design = std::move(d).value();
  return rec;
}

void JointLoops::Step(double t, const Plant& plant, const std::vector<double>& capacity,
                      std::vector<double>& force_ref) {
  const int nj = plant.num_joints(), nb = plant.num_bundles();
  const Eigen::VectorXd r = LoopReference(plant, t);
  // Gains for this pose: designed once per reference value (a step's target).
  std::vector<control::LoopGains> gains(nj);
  for (int j = 0; j < nj; ++j) {
    auto it = gains_[j].find(r[j]);
    if (it == gains_[j].end()) {
      auto rec = Design(plant, j, r);
      control::LoopGains g;  // no bundle crosses the joint: feedforward only
      if (rec.ok()) {
        g = rec->design.gains;
        designs_.push_back(std::move(rec).value());
      }
      it = gains_[j].emplace(r[j], g).first;
    }
    gains[j] = it->second;
  }
  const Eigen::VectorXd feedforward = plant.StaticTorque(r);
  control::AllocationProblem p;
  p.arms = plant.MomentArms();
  p.torque.resize(nj);
  Eigen::VectorXd trial(nj);
  for (int j = 0; j < nj; ++j) {
    const double e = r[j] - plant.JointAngle(j);
    trial[j] = integral_[j] + e * dT_;
    p.torque[j] = feedforward[j] + gains[j].kp * e + gains[j].ki * trial[j] -
                  gains[j].kd * plant.JointVelocity(j);
  }
  p.cap.resize(nb);
  p.floor.resize(nb);
  p.price = price_;
  for (int i = 0; i < nb; ++i) {
    p.cap[i] = std::max(capacity[i], 1e-9);
    p.floor[i] = task_->co_contraction * p.cap[i];
  }
  Eigen::VectorXd tensions = control::AllocateTensions(p);
  // Whole units: each bundle's controller holds whole on-counts, so the demand is met by the
  // combination of counts that comes nearest it (control::RoundToUnits).
  Eigen::VectorXd unit_force(nb);
  Eigen::VectorXi units(nb);
  for (int i = 0; i < nb; ++i) {
    units[i] = plant.num_units(i);
    unit_force[i] = capacity[i] / units[i];
  }
  tensions = control::RoundToUnits(p, tensions, unit_force, units);
  const Eigen::VectorXd achieved = p.arms * tensions;
  for (int j = 0; j < nj; ++j) {
    // Anti-windup: the integral grows only while the bundles can still deliver what it asks.
    const double e = r[j] - plant.JointAngle(j);
    const double span = p.arms.row(j).cwiseAbs().dot(p.cap);
    const double short_by = p.torque[j] - achieved[j];
    const bool saturated = std::abs(short_by) > 1e-3 * span && short_by * e > 0;
    if (!saturated) integral_[j] = trial[j];
  }
  for (int i = 0; i < nb; ++i) force_ref[i] = tensions[i];
}

}  // namespace recruit::sim
