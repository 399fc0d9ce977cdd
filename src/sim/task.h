// Task: one closed-loop experiment read from a task file (JSON, docs/formats/task.md): the model,
// what is tracked (a bundle's force, or a joint angle through an outer loop), the reference, the
// controller's default settings, payloads and pushes. Task::FromFile validates every field and
// names the file and the field in its errors.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "common/result.h"
#include "control/sampling_period.h"
#include "sim/force_sensor.h"
#include "sim/reference.h"

namespace recruit::sim {

enum class Tracked { kForce, kAngle };

// The recruitment controller's settings; RunOptions may override each.
struct ControllerSettings {
  std::string estimator = "output";  // "output", "kalman", ... (see docs/formats/task.md)
  std::string filter_model;          // filter model file for model-based estimators ("" = none)
  double dT = control::kDefaultDT;   // s, sampling period of the broadcast controller
  double lambda = 0.2;               // gain of the expectation law (the paper's lambda)
  // Kalman estimators: force measurement noise std, N (0 = the estimator's default: the model
  // file's R for kalman-augmented, one settled unit's force for kalman2).
  double force_noise_std = 0;
  // kalman-failures: random-walk variance per control period of the working units' fatigue
  // force scale, estimated online (docs/failures.md); 0 = the scale fixed at 1.
  double force_scale_variance = 0;
  // kalman-failures: the broadcast census every this many s (docs/failures.md section 5; 0 =
  // none). The plant's bundles get the plugin's census block (census_noise at its default) unless
  // their model gives census keys.
  double census_period = 0;
};

// Outer loop of arm tasks: PI(D) on the joint angle error gives a net tendon force; positive
// goes to the agonist (flexor), negative to the antagonist (extensor), each on top of `tone`.
struct OuterLoop {
  double kp = 0;           // N/rad
  double ki = 0;           // N/(rad s)
  double kd = 0;           // N s/rad
  double feedforward = 0;  // N: gravity compensation, feedforward * sin(reference angle)
  double tone = 0;         // N, baseline force of both bundles (co-contraction)
  double max_force = 30;   // N, clamp of each bundle's force reference
};

// An external push: a force (N) and torque (N m) in world axes on a body's centre of mass
// (mjData.xfrc_applied) during [start, start + duration).
struct Push {
  std::string body;
  double start = 0, duration = 0;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();
};

// A payload change: the body's mass is set to `mass` (kg) at time `time` (0 = from the start).
struct Payload {
  std::string body;
  double mass = 0;
  double time = 0;
};

// One joint an angle task drives, with its own reference (rad).
struct DrivenJoint {
  std::string joint;  // a hinge
  Reference reference;
};

// Plant failure settings of one bundle (the plugin's failure and fatigue keys, plugin/README.md
// "Failures and fatigue"): set on the plugin instance that drives the bundle when the task runs.
struct BundleFailures {
  std::string actuator;
  // (plugin config key, value as the plugin reads it), in the plugin's key order.
  std::vector<std::pair<std::string, std::string>> keys;
};

struct Task {
  std::string name;
  std::string description;
  std::string source;      // the task file it came from ("" if built in code)
  std::string model_path;  // MJCF, resolved relative to the task file
  Tracked tracked = Tracked::kForce;
  std::string agonist;     // actuator (SMA bundle) whose force is tracked / the flexor
  std::string antagonist;  // optional second bundle (extensor), "" if none
  std::string joint;       // tracked joint for angle tasks
  double duration = 0;     // s
  double timestep = 0;     // s, physics step override (0 = the model's)
  Reference reference;     // N for force tasks, rad for angle tasks
  ControllerSettings controller;
  // The load cell every bundle's force is read through (noise, resolution, held over dT); the
  // default is an exact sensor. Separate from the filter's own R (controller.force_noise_std).
  SensorParams sensor;
  std::optional<OuterLoop> outer;  // hand-set gains (one joint, agonist/antagonist)
  // The self-tuned loop ("outer_loop": "auto", control/loop_design.h): each driven joint's
  // torque demand from gains designed on the model, shared among the bundles that cross it
  // (control/torque_allocation.h). `joints` lists the driven joints (the one-joint form's
  // `joint` and `reference` become its one entry) and `bundles` the bundles that serve them
  // (empty: every bundle of the model).
  bool auto_loop = false;
  std::vector<DrivenJoint> joints;
  std::vector<std::string> bundles;
  double co_contraction = 0.05;  // least tension of each bundle, fraction of its capacity
  std::vector<Push> pushes;
  std::vector<Payload> payloads;
  double settle_band = 0.10;  // fraction of each step's size used for settling time
  // "failures": {ACTUATOR: {...}}: the bundles whose units fail (none: the model's own keys).
  std::vector<BundleFailures> failures;

  static Result<Task> FromFile(const std::string& path);
  // `source` names the file in errors and resolves relative paths (its directory).
  static Result<Task> FromJsonText(const std::string& text, const std::string& source);
};

// Sets `key`'s value in the plugin instance `instance` of an MJCF text (adds the config line if
// the key is not there): how a task's failure keys and a sweep's model axes reach the plugin.
Result<std::string> SetPluginConfig(const std::string& xml, const std::string& instance,
                                    const std::string& key, const std::string& value);

}  // namespace recruit::sim
