// The self-tuned joint loops of an "outer_loop": "auto" task (src/sim/joint_loop.h) frozen for
// `recruit export`: everything the loop computes from MuJoCo, computed here once per reference
// pose of the task's schedule, so that the exported C code needs no MuJoCo (docs/export.md,
// "Self-tuned loops").
//
// What JointLoops::Step reads from the model, and when:
//  - per reference value of a joint (first time it is seen): the loop's gains
//    (JointLoops::Design) and how the bundles hold the pose (the stiffness rows);
//  - per control instant, but a function of the reference pose only (with the limb's other joints
//    and the payloads as they are): the static torque (mj_inverse), the moment arms and each
//    bundle's unit force at the pose;
//  - per control instant from the sensors: the driven joints' angles and velocities and each
//    bundle's length coordinate (already an input of the package).
// So a table over the schedule's distinct reference poses holds the first two exactly; the
// allocation, rounding to whole units, anti-windup and the force references run in C.
#pragma once

#include <string>
#include <vector>

#include "common/result.h"
#include "export/c_writer.h"
#include "sim/run_task.h"
#include "sim/task.h"

namespace recruit::exporter {

// One driven joint's setting at a pose: the loop's gains and, when a design was made, the
// bundles' stiffness per newton of tension (the allocation's stiffness row).
struct FrozenJointSetting {
  double kp = 0, ki = 0, kd = 0;
  bool holds = false;        // false: no bundle crosses the joint (feedforward only)
  std::vector<double> coef;  // per bundle, N m/rad per N (JointHolding::coef)
  double limb_stiffness = 0;
};

// One reference pose of the schedule (the driven joints' loop references, rad).
struct FrozenPose {
  std::vector<double> reference;    // per joint, after the limits' margin
  std::vector<double> feedforward;  // per joint, N m: Plant::StaticTorque at the pose
  std::vector<double> arms;         // joints x bundles, row-major: Plant::MomentArmsAt
  std::vector<double> unit_force;   // per bundle, N: an on unit's force at the pose's length
  std::vector<FrozenJointSetting> joint;
  double first_time = 0;  // s, the first control instant at this pose
};

struct FrozenAutoLoop {
  std::vector<std::string> joints;
  std::vector<int> limited;           // per joint: its reference is clamped to [lo, hi]
  std::vector<double> lo, hi;         // rad, the range less the loop's margin
  std::vector<double> price;          // per bundle (JointLoops' allocation prices)
  std::vector<int> held_only;         // per bundle: no transient share (JointLoops::held_only)
  std::vector<int> units;             // per bundle
  double co_contraction = 0, dT = 0;  // fraction of capacity; s
  std::vector<FrozenPose> poses;      // in the order the schedule reaches them
  std::vector<std::string> notes;     // what the table assumes (other joints, payloads)
};

// The frozen loop of `task` with `options` applied: the plant loaded and reset with
// options.seed, the bundles' unit force maps those of `controllers` (sim::TaskControllers, plant
// order), the designs made in the order the run makes them (control instants every dT of the
// task's duration, the limb starting at rest where the plant's reset puts it).
Result<FrozenAutoLoop> FreezeAutoLoop(const sim::Task& task, const sim::RunOptions& options,
                                      const std::vector<sim::BundleController>& controllers);

// The package's pieces for the frozen loop: the header's defines, the controller's loop state,
// the input's joint fields, recruit_init's lines and the C of the loop (the constants and
// force_references), placed at the templates' @LOOP_DEFINES@, @LOOP_STATE@, @LOOP_INPUT@,
// @LOOP_INIT@ and @OUTER@.
struct LoopCode {
  std::string defines, state, input, init, outer;
};
LoopCode AutoLoopCode(const FrozenAutoLoop& loop, const Writer& w);

}  // namespace recruit::exporter
