// JointLoops: the self-tuned outer loop of an angle task ("outer_loop": "auto"). At each control
// instant every driven joint's torque demand is the static torque of its reference pose
// (Plant::StaticTorque) plus a PID on its angle error, with gains designed on the model
// (control/loop_design.h) for the pose of each new reference value; the demands are then shared
// among the bundles by their moment arms and capacities (control/torque_allocation.h), which
// gives each bundle's force reference. docs/controller.md, "The self-tuned outer loop".
#pragma once

#include <map>
#include <string>
#include <vector>

#include "common/result.h"
#include "control/actuator_response.h"
#include "control/loop_design.h"
#include "sim/plant.h"
#include "sim/task.h"

namespace recruit::sim {

// One design of one joint's loop: at which reference, on what model, with what prediction.
struct JointDesignRecord {
  std::string joint;
  double reference = 0;  // rad
  control::JointDynamics dynamics;
  double actuator_t63 = 0;  // s, the design's bundle response: its time to 63 % of a step
  control::LoopDesign design;
};

class JointLoops {
 public:
  // `responses`: each bundle's tension step response (control/actuator_response.h), in the
  // plant's bundle order. `dT` the sampling period.
  static Result<JointLoops> Create(const Task& task, const Plant& plant,
                                   std::vector<control::ActuatorResponse> responses, double dT);

  // The force reference (N) of every bundle at a control instant; `capacity` is each bundle's
  // tension with every unit on at its present length.
  void Step(double t, const Plant& plant, const std::vector<double>& capacity,
            std::vector<double>& force_ref);

  // Every design made so far, in the order made.
  const std::vector<JointDesignRecord>& designs() const { return designs_; }
  // The driven joints' references at t, kept 3 % of each limited joint's range inside it.
  Eigen::VectorXd LoopReference(const Plant& plant, double t) const;
  // Designs the loop of joint j for the reference value r (the other joints at theirs).
  Result<JointDesignRecord> Design(const Plant& plant, int j, const Eigen::VectorXd& r) const;

 private:
  const Task* task_ = nullptr;
  std::vector<control::ActuatorResponse> responses_;
  double dT_ = 0;
  control::LoopTarget target_;
  std::vector<std::map<double, control::LoopGains>> gains_;  // per joint, by reference value
  std::vector<double> integral_;                             // rad s, per joint
  Eigen::VectorXd price_;  // per bundle: its time to 63 % over the fastest bundle's
  std::vector<JointDesignRecord> designs_;
};

// The shortest time a reference holds a value over [0, duration] (its steps' holds), or the
// duration when it never changes.
double ShortestHold(const Reference& reference, double duration);

}  // namespace recruit::sim
