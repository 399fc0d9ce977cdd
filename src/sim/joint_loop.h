// JointLoops: the self-tuned outer loop of an angle task ("outer_loop": "auto"). At each control
// instant every driven joint's torque demand is the static torque of its reference pose
// (Plant::StaticTorque) plus a PID on its angle error, with gains designed on the model
// (control/loop_design.h) for the pose of each new reference value. The demands are shared
// among the bundles by their moment arms and capacities at the reference pose
// (control/torque_allocation.h), with co-contraction where a joint would otherwise be held with
// too little stiffness, and each bundle's share becomes an on-count at the reference pose: the
// force reference its controller gets is that count's force at the present length, so the
// count does not chase the limb as it moves and the bundles' own stiffness keeps acting.
// docs/controller.md, "The self-tuned outer loop".
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "common/result.h"
#include "control/actuator_response.h"
#include "control/loop_design.h"
#include "control/torque_allocation.h"
#include "sim/holding.h"
#include "sim/plant.h"
#include "sim/task.h"

namespace recruit::sim {

// One design of one joint's loop: at which reference, on what model, with what prediction.
struct JointDesignRecord {
  std::string joint;
  double reference = 0;             // rad
  control::JointDynamics dynamics;  // stiffness: the limb's and the bundles' (below), summed
  // The bundles' share of the stiffness at constant on-counts, holding the reference with the
  // tensions the allocation gives there: their force-length slope (stabilising) and the change of
  // their moment arms with the angle (either sign). N m/rad.
  double bundle_stiffness = 0;
  JointHolding holding;
  double step = 0;          // rad, the step designed for
  double torque_error = 0;  // N m, the feedforward error the integral must remove
  double actuator_t63 = 0;  // s, the design's bundle response: its time to 63 % of a step
  control::LoopDesign design;
  double dT = 0;               // s, the loop's sampling period
  control::LoopTarget target;  // what the design asked of the step
  // The joint's torque response each way for this step (JointLoops::BothWays) and its release's
  // time to 63 % (s): not a design input; control::PredictStep with it shows the design's gains
  // as the bundles will move the demand each way (recruit tune-loop).
  control::ActuatorResponse both_ways;
  double release_t63 = 0;
  // The joint's resolution: for each bundle that crosses it (name, rad), the angle one more unit
  // on moves it against the stiffness and kp, |arm| x unit force at the reference / (stiffness +
  // kp); the count estimate's error of a few units moves the held pose by as many times this.
  std::vector<std::pair<std::string, double>> unit_angle;
};

class JointLoops {
 public:
  // `responses`: each bundle's tension step response (control/actuator_response.h), and
  // `on_unit_force` each bundle's unit force map, in the plant's bundle order. `dT` the sampling
  // period.
  static Result<JointLoops> Create(const Task& task, const Plant& plant,
                                   std::vector<control::ActuatorResponse> responses,
                                   std::vector<UnitForce> on_unit_force, double dT);

  // The force reference (N) of every bundle at a control instant.
  void Step(double t, const Plant& plant, std::vector<double>& force_ref);

  // Each bundle's price in the allocation (BundlePrices).
  const Eigen::VectorXd& prices() const { return price_; }
  // Per bundle: whether it takes no share of the loop's transient terms (HeldOnlyBundles).
  const std::vector<bool>& held_only() const { return held_only_; }
  // Per joint, the PID's integral term (N m): the sum of ki e dT over the instants the bundles
  // could deliver it, each with the gain of its own design.
  const std::vector<double>& integral() const { return integral_; }
  // Every design made so far, in the order made.
  const std::vector<JointDesignRecord>& designs() const { return designs_; }
  // The driven joints' references at t, kept 3 % of each limited joint's range inside it.
  Eigen::VectorXd LoopReference(const Plant& plant, double t) const;
  // Designs the loop of joint j for a step of size `step` (rad) to the reference value r (the
  // other joints at theirs).
  Result<JointDesignRecord> Design(const Plant& plant, int j, const Eigen::VectorXd& r,
                                   double step) const;
  // Joint j's torque response for a step of sign `step` to pose r, each way: s for the demand
  // moving the step's way, release for it moving back. A rise of the torque is as slow as the
  // slower of the fastest flexing bundle's rise and the fastest extending bundle's release
  // (control::PredictBundleResponse), a fall the other way round. dT 0 when no bundle crosses j.
  control::ActuatorResponse BothWays(const Plant& plant, int j, const Eigen::VectorXd& r,
                                     double step) const;
  // How the bundles hold joint j at pose r (sim/holding.h).
  JointHolding HoldingAt(const Plant& plant, int j, const Eigen::VectorXd& r) const;

 private:
  const Task* task_ = nullptr;
  std::vector<control::ActuatorResponse> responses_;
  std::vector<UnitForce> on_unit_force_;
  double dT_ = 0;
  control::LoopTarget target_;
  // Per joint, by reference value: the loop's gains and how the bundles hold the pose.
  struct Setting {
    control::LoopGains gains;
    JointHolding holding;
  };
  std::vector<std::map<double, Setting>> settings_;

  std::vector<bool> held_only_;      // per bundle: HeldOnlyBundles at the first reference pose
  std::vector<double> integral_;     // N m, per joint: the sum of ki e dT
  std::vector<double> last_target_;  // rad, per joint: NaN before the first instant
  Eigen::VectorXd price_;            // per bundle: its time to 63 % over the fastest bundle's
  std::vector<JointDesignRecord> designs_;
};

// Each bundle's price in the torque allocation (control::AllocationProblem::price): its time to
// 63 % over the fastest bundle's, times kCrossedJointPrice (10) for each driven joint it crosses
// beyond the first (`arms`: joints x bundles, at the first reference pose; an arm of rounding
// size, below 1e-9 of the largest, is not a crossing). Slow bundles take what only they can
// give; a bundle on several joints moves one of them only where the others' bundles cannot, as
// cancelling its torque on the other joint with bundles of another speed makes that joint jump.
Eigen::VectorXd BundlePrices(const std::vector<control::ActuatorResponse>& responses,
                             const Eigen::MatrixXd& arms);

// The bundles that take no share of the loop's transient terms (kp e - kd qdot): those that cross
// more than one driven joint (`arms`: joints x bundles; an arm below 1e-9 of the largest is not a
// crossing) where every joint they cross has a bundle that crosses it alone pulling each way.
// Moving one joint with such a bundle moves the other too, and the other's bundles, of another
// speed, cancel that first: the two-joint arm's elbow, thrown 20 deg one way and then to its
// limit by the shoulder's share of its biarticular flexor (seed 602 at 80 s).
std::vector<bool> HeldOnlyBundles(const Eigen::MatrixXd& arms);

// The tensions that meet the demand `p` (with the stiffness rows of `holding`, AllocateHolding)
// when the bundles marked `held_only` keep their tensions `held` (the allocation of the static
// torque and the integral alone): the others take all of the loop's transient share.
// AllocateHolding(p, holding) when none is marked.
Eigen::VectorXd AllocateTransient(const control::AllocationProblem& p,
                                  const std::vector<const JointHolding*>& holding,
                                  const Eigen::VectorXd& held, const std::vector<bool>& held_only);

// The tensions (at the reference pose's unit forces) whose counts deliver `demanded` where the
// limb is. A count pulls its unit force at the present length, which far from the reference can
// be several times the reference pose's (a long unit is stretched more): the loop's transient
// share of a bundle (demanded - held) is scaled by the reference's unit force over the present
// one where the present one is larger, so that the designed demand, not a multiple of it, moves
// the limb (the two-joint arm's elbow: 0.5 against 0.11 N per unit of its extensor at the start
// and the end of a 22 deg step). Where the present unit force is smaller the count is not raised
// to make up for it: a bundle that is short is where the limb has gone its way.
Eigen::VectorXd DeliveredAtPresentPose(const Eigen::VectorXd& held, const Eigen::VectorXd& demanded,
                                       const Eigen::VectorXd& ref_unit_force,
                                       const Eigen::VectorXd& present_unit_force);

// The shortest time a reference holds a value over [0, duration] (its steps' holds), or the
// duration when it never changes.
double ShortestHold(const Reference& reference, double duration);

}  // namespace recruit::sim
