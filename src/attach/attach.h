// `recruit attach`: the named muscles (or any tendon actuators) of a user's MJCF become sized
// recruit.sma bundles on the same tendons, in a copy of the model written through mjSpec.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "attach/damper.h"
#include "attach/holdable.h"
#include "attach/holding_load.h"
#include "attach/joint_lock.h"
#include "attach/lengthrange.h"
#include "attach/sizing.h"
#include "common/result.h"

namespace recruit::attach {

struct AttachOptions {
  std::string model;                 // input MJCF
  std::vector<std::string> muscles;  // actuator names, or {"all"}: every muscle on a tendon
  std::string output;                // written model ("" with size_only)
  std::string task;                  // starter task to write ("" = none)
  std::string report;                // JSON report to write ("" = none)
  bool size_only = false;            // design only: nothing written but the report
  double force = std::nan("");       // peak force for every bundle (N); NaN = the muscle's F0
  bool lengthrange_from_joints = false;
  // Joints held at their reference value in the written model (and not driven by the task).
  std::vector<std::string> lock;
  SizingLimits limits;
};

struct JointUse {  // a joint a bundle's tendon crosses
  std::string joint;
  bool hinge = true;
  double lo = 0, hi = 0;                // joint range (rad or m)
  double usable_lo = 0, usable_hi = 0;  // cut at tendon-path jumps
  double arm = 0;                       // m: the tendon's dL/dq at qpos0
};

struct BundleReport {
  std::string name;  // actuator (kept)
  std::string tendon;
  int tendon_id = -1;
  std::string replaced;  // what it was: "muscle" or "general"
  double peak_force = 0;
  std::string force_source;  // "muscle F0" or "--force"
  std::vector<JointUse> joints;
  std::vector<std::string> jumps;  // "elbow at 114 deg (376.0 -> 211.0 mm)"
  // The free joint the moved joints hang from ("" when the limb's base is fixed).
  std::string free_base;
  double length_min = 0, length_max = 0, ref_length = 0;
  HoldingLoad holding;  // the limb's own weight at the tendon (sizing's resolution)
  std::string instance, sensor;
  BundleDesign design;
};

struct AttachReport {
  std::string model, output, task;
  std::vector<BundleReport> bundles;
  std::vector<LengthRangeFix> lengthranges;  // other muscles' ranges set from the joints
  // With --lock: the other muscles' ranges as MuJoCo computes them on the free limb, written
  // before the locks (lengthrange.h, FreezeLengthRanges).
  std::vector<LengthRangeFix> lengthranges_unlocked;
  std::vector<JointLock> locks;
  // The joints the bundles move (not locked), with the damping their dampers give them.
  std::vector<DampedJoint> damped_joints;
  // The starter task's driven joints: the part of each usable range the bundles hold
  // (attach/holdable.h; with --task only).
  std::vector<HoldableRange> holdable;
  std::vector<std::string> changes;  // one line per edit
  std::vector<std::string> warnings;
};

// Does it all: parse, probe the original, size, edit, check that the result compiles and loads,
// write the model, task and report atomically. Nothing is written on error.
Result<AttachReport> Attach(const AttachOptions& options);

}  // namespace recruit::attach
