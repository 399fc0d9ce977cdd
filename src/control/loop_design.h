// The outer loop of a driven joint, designed from the model instead of tuned by hand
// (docs/controller.md, "The self-tuned outer loop").
//
// Each control instant (every dT) the joint's torque demand is
//   tau = tau_static(r) + kp e + ki sum(e dT) - kd qdot,   e = r - q,
// with tau_static(r) the torque that holds the limb still at the reference (MuJoCo's inverse
// dynamics: gravity, payload, passive springs). The design model about the reference is the
// joint's linearised mechanics  I qddot + b qdot + k q = tau_act  and the bundles' tension
// response (control/actuator_response.h) between the demand and tau_act. The gains are chosen
// on a grid by simulating that model: the fastest settling into the band with the stated
// overshoot, that also keeps settling (overshoot <= 25 %) with the actuator 1.5x slower and the
// loop gain 1.5x higher, and when the static torque of the new pose is off by half the
// step's plus LoopTarget::torque_error (an error only the integral removes: the bundles' force
// model, the estimate's bias).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/result.h"
#include "control/actuator_response.h"

namespace recruit::control {

// The joint about the reference pose.
struct JointDynamics {
  double inertia = 0;    // kg m^2 (mass matrix diagonal + armature), > 0
  double damping = 0;    // N m s/rad, >= 0
  double stiffness = 0;  // N m/rad: d tau_static / dq (gravity, springs); may be <= 0
};

struct LoopGains {
  double kp = 0;  // N m/rad
  double ki = 0;  // N m/(rad s)
  double kd = 0;  // N m s/rad, on the measured velocity
};

// What the design asks of a step response.
struct LoopTarget {
  double overshoot = 0.05;  // fraction of the step
  double band = 0.10;       // settling band, fraction of the step
  double hold = 20;         // s, time a step has to settle
  // N m per unit of the step: an error of the feedforward that only the integral removes (the
  // bundles' force falling short of their references), on top of half the joint's stiffness.
  double torque_error = 0;
};

struct PredictedStep {
  double overshoot = 0;      // fraction of the step
  double settling_time = 0;  // s (the hold when it never settles)
  bool settled = false;
  double final_error = 0;           // |angle - 1| at the end of the hold
  std::vector<double> time, angle;  // at the control instants; angle as a fraction of the step
};

struct LoopDesign {
  LoopGains gains;
  PredictedStep nominal;  // the design model
  PredictedStep robust;   // actuator 1.5x slower, loop gain 1.5x
  PredictedStep offset;   // the feedforward off by half the step's static torque
  PredictedStep delayed;  // every change of the demand shown one sampling period late
  bool meets = false;     // nominal, robust and offset meet the target (else the closest)
  std::string note;
};

// The design model's response to a unit step of the reference; `feedforward_error` (N m) is
// taken off every demand from the step on. Each rise of the demand moves the actuator's torque
// along act.s, each fall along its release response (ActuatorResponse::Released, s when it has
// none): the torque is the sum of the demand's increments, each through its own direction's
// response, which starts `delay` s after the change (a dead time on top of the response's own).
PredictedStep PredictStep(const JointDynamics& joint, const ActuatorResponse& act, double dT,
                          const LoopGains& gains, const LoopTarget& target,
                          double actuator_slowdown = 1, double gain_scale = 1,
                          double feedforward_error = 0, double delay = 0);

// The exact bits of every input of DesignJointLoop: the key its designs are kept under, in this
// process and between processes (control/loop_design_store.h).
std::vector<std::uint64_t> LoopDesignKey(const JointDynamics& joint, const ActuatorResponse& act,
                                         double dT, const LoopTarget& target);

Result<LoopDesign> DesignJointLoop(const JointDynamics& joint, const ActuatorResponse& act,
                                   double dT, const LoopTarget& target);

}  // namespace recruit::control
