#include "sim/joint_loop.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "control/torque_allocation.h"
#include "sim/loop_constants.h"

namespace recruit::sim {
namespace {

// How far the bundles' tension may fall short of its reference at a hold, as a fraction: the
// unit force map's error and the estimate's bias (MyoSuite's elbow, attached with --force 150:
// 6-25 % at the holds of seed 401).
constexpr double kForceError = 0.15;
constexpr double kLeastStep = 0.05;  // rad: the least step a design assumes
// The price factor of a bundle per further driven joint it crosses: moving one joint with it
// needs the other joint's bundles to cancel its torque there, and their different speeds make
// that joint jump in between (the two-joint arm's elbow thrown to its limits by the biarticular
// flexor's shoulder share; seeds 401-403: worst overshoot 76 -> 58 % at dT 1).
constexpr double kCrossedJointPrice = 10;

}  // namespace

std::vector<bool> HeldOnlyBundles(const Eigen::MatrixXd& arms) {
  const int nj = static_cast<int>(arms.rows()), nb = static_cast<int>(arms.cols());
  const double tiny = 1e-9 * arms.cwiseAbs().maxCoeff();
  std::vector<int> crossed(nb, 0);
  for (int i = 0; i < nb; ++i) {
    for (int j = 0; j < nj; ++j) crossed[i] += std::abs(arms(j, i)) > tiny;
  }
  // Per joint, whether a bundle that crosses it alone pulls it each way.
  std::vector<bool> both_ways(nj);
  for (int j = 0; j < nj; ++j) {
    bool up = false, down = false;
    for (int i = 0; i < nb; ++i) {
      if (crossed[i] != 1) continue;
      up |= arms(j, i) > tiny;
      down |= arms(j, i) < -tiny;
    }
    both_ways[j] = up && down;
  }
  std::vector<bool> out(nb, false);
  for (int i = 0; i < nb; ++i) {
    if (crossed[i] < 2) continue;
    out[i] = true;
    for (int j = 0; j < nj; ++j) {
      if (std::abs(arms(j, i)) > tiny && !both_ways[j]) out[i] = false;
    }
  }
  return out;
}

Eigen::VectorXd AllocateTransient(const control::AllocationProblem& p,
                                  const std::vector<const JointHolding*>& holding,
                                  const Eigen::VectorXd& held, const std::vector<bool>& held_only) {
  if (std::find(held_only.begin(), held_only.end(), true) == held_only.end()) {
    return AllocateHolding(p, holding);
  }
  control::AllocationProblem q = p;
  for (int i = 0; i < static_cast<int>(held_only.size()); ++i) {
    if (!held_only[i]) continue;
    // Held: floor and cap at its tension (control::AllocationProblem::floor), a cap above 0.
    q.floor[i] = q.cap[i] = std::max(held[i], 1e-9);
  }
  return AllocateHolding(q, holding);
}

Eigen::VectorXd BundlePrices(const std::vector<control::ActuatorResponse>& responses,
                             const Eigen::MatrixXd& arms) {
  double fastest = std::numeric_limits<double>::infinity();
  for (const control::ActuatorResponse& r : responses) fastest = std::min(fastest, r.TimeTo(0.63));
  const double tiny = 1e-9 * arms.cwiseAbs().maxCoeff();
  Eigen::VectorXd price(responses.size());
  for (int i = 0; i < price.size(); ++i) {
    price[i] = responses[i].TimeTo(0.63) / fastest;
    for (int j = 0, crossed = 0; j < arms.rows(); ++j) {
      if (std::abs(arms(j, i)) > tiny && ++crossed > 1) price[i] *= kCrossedJointPrice;
    }
  }
  return price;
}

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
                                      std::vector<control::ActuatorResponse> responses,
                                      std::vector<UnitForce> on_unit_force, double dT) {
  if (static_cast<int>(responses.size()) != plant.num_bundles() ||
      static_cast<int>(on_unit_force.size()) != plant.num_bundles()) {
    return Error{"joint loops: one actuator response and unit force map per bundle is needed"};
  }
  JointLoops loops;
  loops.task_ = &task;
  loops.responses_ = std::move(responses);
  loops.on_unit_force_ = std::move(on_unit_force);
  loops.dT_ = dT;
  loops.target_.band = task.settle_band;
  // The hold a step has to settle in: the shortest of the task's steps, at most 60 s (a longer
  // hold would only allow a slower design).
  double hold = 60;
  for (const DrivenJoint& d : task.joints) {
    hold = std::min(hold, ShortestHold(d.reference, task.duration));
  }
  loops.target_.hold = std::max(hold, 4 * dT);
  loops.last_target_.assign(plant.num_joints(), std::nan(""));
  loops.settings_.resize(plant.num_joints());
  loops.integral_.assign(plant.num_joints(), 0.0);
  const Eigen::MatrixXd arms = plant.MomentArmsAt(loops.LoopReference(plant, 0));
  loops.price_ = BundlePrices(loops.responses_, arms);
  loops.held_only_ = HeldOnlyBundles(arms);
  return loops;
}

JointHolding JointLoops::HoldingAt(const Plant& plant, int j, const Eigen::VectorXd& r) const {
  return HoldJoint(plant, j, r, on_unit_force_, task_->co_contraction, price_);
}

Result<JointDesignRecord> JointLoops::Design(const Plant& plant, int j, const Eigen::VectorXd& r,
                                             double step) const {
  JointDesignRecord rec;
  rec.joint = plant.joint_name(j);
  rec.reference = r[j];
  rec.holding = HoldingAt(plant, j, r);
  rec.bundle_stiffness = rec.holding.stiffness;
  rec.step = std::max(std::abs(step), kLeastStep);
  rec.torque_error = kForceError * rec.holding.torque;
  rec.dynamics.stiffness = rec.holding.limb_stiffness + rec.bundle_stiffness;
  rec.dynamics.inertia = plant.JointInertia(j, r);
  rec.dynamics.damping = plant.JointDamping(j, r);
  // The response of the joint's torque: the allocation gives a demand to the fastest bundles
  // that can meet it, so the slower of the fastest bundle on each side sets it.
  // Arms at the reference pose, so the design does not depend on where the limb is; a bundle
  // that does not cross the joint has an arm of rounding size, of either sign.
  const Eigen::MatrixXd arms = plant.MomentArmsAt(r);
  const double tiny = 1e-9 * arms.row(j).cwiseAbs().maxCoeff();
  const control::ActuatorResponse* side[2] = {nullptr, nullptr};  // flexing, extending
  for (int i = 0; i < plant.num_bundles(); ++i) {
    if (std::abs(arms(j, i)) <= tiny) continue;
    const control::ActuatorResponse*& s = side[arms(j, i) > 0 ? 0 : 1];
    if (s == nullptr || responses_[i].TimeTo(0.63) < s->TimeTo(0.63)) s = &responses_[i];
  }
  const control::ActuatorResponse* act = side[0];
  if (act == nullptr || (side[1] != nullptr && side[1]->TimeTo(0.63) > act->TimeTo(0.63))) {
    act = side[1];
  }
  if (act == nullptr) return Error{"joint '" + rec.joint + "': no bundle of the task crosses it"};
  rec.actuator_t63 = act->TimeTo(0.63);
  control::LoopTarget target = target_;
  target.torque_error = rec.torque_error / rec.step;
  // Designed on the rise both ways (docs/controller.md, "Rise and release").
  control::ActuatorResponse rise = *act;
  rise.release.clear();
  auto d = control::DesignJointLoop(rec.dynamics, rise, dT_, target);
  if (!d.ok()) return d.failure().In("joint '" + rec.joint + "': ");
  rec.design = std::move(d).value();
  rec.dT = dT_;
  rec.target = target;
  // Each way of the demand through the bundles that move it that way (not a design input).
  rec.both_ways = BothWays(plant, j, r, step);
  rec.release_t63 = rec.both_ways.Released().TimeTo(0.63);
  const Eigen::VectorXd lengths = plant.UnitLengthsAt(r);
  const double holding = rec.dynamics.stiffness + rec.design.gains.kp;
  for (int i = 0; i < plant.num_bundles(); ++i) {
    if (std::abs(arms(j, i)) <= tiny) continue;
    const double torque = std::abs(arms(j, i)) * on_unit_force_[i](lengths[i]);
    rec.unit_angle.emplace_back(
        plant.bundle_name(i),
        holding > 0 ? torque / holding : std::numeric_limits<double>::infinity());
  }
  return rec;
}

control::ActuatorResponse JointLoops::BothWays(const Plant& plant, int j, const Eigen::VectorXd& r,
                                               double step) const {
  const Eigen::MatrixXd arms = plant.MomentArmsAt(r);
  const double tiny = 1e-9 * arms.row(j).cwiseAbs().maxCoeff();
  // The fastest rise and release of each side (flexing, extending) by their times to 63 %.
  struct Fastest {
    double t63 = std::numeric_limits<double>::infinity();
    const control::ActuatorResponse* r = nullptr;
    bool release = false;
    void Take(const control::ActuatorResponse& b, bool back) {
      const double t = back ? b.Released().TimeTo(0.63) : b.TimeTo(0.63);
      if (t < t63) t63 = t, r = &b, release = back;
    }
    const std::vector<double>& s() const {
      return release && !r->release.empty() ? r->release : r->s;
    }
  };
  Fastest rise[2], release[2];
  for (int i = 0; i < plant.num_bundles(); ++i) {
    if (std::abs(arms(j, i)) <= tiny) continue;
    const int side = arms(j, i) > 0 ? 0 : 1;
    rise[side].Take(responses_[i], false);
    release[side].Take(responses_[i], true);
  }
  // The slower of two ways of moving the torque (either side may have no bundle): a rise of the
  // joint's torque is a flexing bundle's rise or an extending one's release.
  auto slower = [](const Fastest& a, const Fastest& b) {
    return a.r == nullptr || (b.r != nullptr && b.t63 > a.t63) ? b : a;
  };
  const Fastest up = slower(rise[0], release[1]), down = slower(release[0], rise[1]);
  control::ActuatorResponse out;
  if (up.r == nullptr) return out;
  // Oriented for the step: s for the demand moving the step's way, release for the other.
  const Fastest& ahead = step >= 0 ? up : down;
  const Fastest& back = step >= 0 ? down : up;
  out.dT = ahead.r->dT;
  out.s = ahead.s();
  if (back.r->dT == out.dT && back.s() != out.s) out.release = back.s();
  return out;
}

void JointLoops::Step(double t, const Plant& plant, std::vector<double>& force_ref) {
  const int nj = plant.num_joints(), nb = plant.num_bundles();
  const Eigen::VectorXd r = LoopReference(plant, t);
  // Gains for this pose: designed once per reference value (a step's target).
  std::vector<control::LoopGains> gains(nj);
  std::vector<const JointHolding*> holding(nj, nullptr);
  for (int j = 0; j < nj; ++j) {
    // The step a new reference value makes: from the last one, or from the limb at the start.
    const double from = std::isnan(last_target_[j]) ? plant.JointAngle(j) : last_target_[j];
    last_target_[j] = r[j];
    auto it = settings_[j].find(r[j]);
    if (it == settings_[j].end()) {
      auto rec = Design(plant, j, r, r[j] - from);
      Setting set;  // no bundle crosses the joint: feedforward only
      if (rec.ok()) {
        set = {rec->design.gains, rec->holding};
        designs_.push_back(std::move(rec).value());
      }
      it = settings_[j].emplace(r[j], set).first;
    }
    gains[j] = it->second.gains;
    if (it->second.holding.coef.size() == nb) holding[j] = &it->second.holding;
  }
  const Eigen::VectorXd feedforward = plant.StaticTorque(r);
  // The bundles are set for the reference pose: arms and unit forces there. Each bundle's
  // on-count is its tension there over its unit force there, and the force reference handed to
  // its controller is that count at the present length, so the count does not follow the limb
  // as it moves and the bundles' own force-length stiffness keeps acting.
  const Eigen::VectorXd ref_lengths = plant.UnitLengthsAt(r);
  control::AllocationProblem p;
  p.arms = plant.MomentArmsAt(r);
  p.torque.resize(nj);
  Eigen::VectorXd trial(nj);
  for (int j = 0; j < nj; ++j) {
    const double e = r[j] - plant.JointAngle(j);
    // The integral is kept as torque, so a new design's ki takes over what the last one
    // integrated without a jump (bumpless).
    trial[j] = integral_[j] + gains[j].ki * e * dT_;
    p.torque[j] =
        feedforward[j] + gains[j].kp * e + trial[j] - gains[j].kd * plant.JointVelocity(j);
  }
  p.cap.resize(nb);
  p.floor.resize(nb);
  p.price = price_;
  Eigen::VectorXd unit_force(nb);
  Eigen::VectorXi units(nb);
  for (int i = 0; i < nb; ++i) {
    units[i] = plant.num_units(i);
    unit_force[i] = on_unit_force_[i](ref_lengths[i]);
    p.cap[i] = std::max(units[i] * unit_force[i], 1e-9);
    p.floor[i] = task_->co_contraction * p.cap[i];
  }
  const Eigen::VectorXd continuous = AllocateHolding(p, holding);
  const Eigen::VectorXd achieved = p.arms * continuous;
  for (int j = 0; j < nj; ++j) {
    // Anti-windup: the integral grows only while the bundles can still deliver what it asks.
    const double e = r[j] - plant.JointAngle(j);
    const double span = p.arms.row(j).cwiseAbs().dot(p.cap);
    const double short_by = p.torque[j] - achieved[j];
    const bool saturated = std::abs(short_by) > 1e-3 * span && short_by * e > 0;
    if (!saturated) integral_[j] = trial[j];
  }
  Eigen::VectorXd present_force(nb);
  for (int i = 0; i < nb; ++i) present_force[i] = on_unit_force_[i](plant.UnitLength(i));
  // The tensions that hold the reference pose: the static torque plus the integral, without the
  // loop's transient share (kp e - kd qdot).
  control::AllocationProblem hold = p;
  hold.torque = feedforward + trial;
  const Eigen::VectorXd held = AllocateHolding(hold, holding);
  // The loop's transient share moves the one-joint bundles only (HeldOnlyBundles). The
  // anti-windup above stays on the whole demand: the integral is how a bundle that is held
  // takes up a lasting demand (through `held`), so it grows while all the bundles can deliver it.
  const bool any_held_only =
      std::find(held_only_.begin(), held_only_.end(), true) != held_only_.end();
  const Eigen::VectorXd moving =
      any_held_only ? AllocateTransient(p, holding, held, held_only_) : continuous;
  const Eigen::VectorXd aimed = DeliveredAtPresentPose(held, moving, unit_force, present_force);
  // Whole units: each bundle's controller holds whole on-counts, so the demand is met by the
  // combination of counts that comes nearest it (control::RoundToUnits).
  control::AllocationProblem whole = p;
  for (int j = 0; j < nj; ++j) {  // term by term, as the exported C sums it
    whole.torque[j] = p.arms(j, 0) * aimed[0];
    for (int i = 1; i < nb; ++i) whole.torque[j] += p.arms(j, i) * aimed[i];
  }
  const Eigen::VectorXd tensions = control::RoundToUnits(whole, aimed, unit_force, units);
  for (int i = 0; i < nb; ++i) {
    const double count = unit_force[i] > 0 ? tensions[i] / unit_force[i] : 0.0;
    force_ref[i] = count * present_force[i];
  }
}

Eigen::VectorXd DeliveredAtPresentPose(const Eigen::VectorXd& held, const Eigen::VectorXd& demanded,
                                       const Eigen::VectorXd& ref_unit_force,
                                       const Eigen::VectorXd& present_unit_force) {
  Eigen::VectorXd out = demanded;
  for (int i = 0; i < out.size(); ++i) {
    if (present_unit_force[i] > ref_unit_force[i] && ref_unit_force[i] > 0) {
      out[i] = held[i] + (demanded[i] - held[i]) * ref_unit_force[i] / present_unit_force[i];
    }
  }
  return out;
}

}  // namespace recruit::sim
