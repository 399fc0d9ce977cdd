// RunTask: one closed-loop run of a task (plant = the MuJoCo model with its SMA bundles,
// estimator, broadcast controller, optional outer angle loop), reporting every physics step to
// the observers (CSV writer, video recorder) and returning the run's metrics.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "common/result.h"
#include "common/step_observer.h"
#include "control/broadcast.h"
#include "control/recruitment_controller.h"
#include "sim/metrics.h"
#include "sim/run_metrics.h"
#include "sim/task.h"

namespace recruit::sim {

// What the controllers see and decide at one control instant (ControlInstantHook), per bundle
// (agonist first).
struct ControlInstant {
  double time = 0;                         // s
  double reference = 0;                    // the task's reference at `time` (N or rad)
  double angle = 0, angular_velocity = 0;  // the tracked joint's encoder (0 without one)
  std::vector<double> sensed_force;        // N, each load cell's reading
  std::vector<double> tendon_length;       // m, each bundle's length coordinate (UnitLength)
  // Decided: each bundle's force reference, broadcast, on-count estimate and its variance.
  std::vector<double> force_reference;
  std::vector<control::Broadcast> broadcast;
  std::vector<double> estimated_on, estimated_on_variance;
  // Failure-aware estimators: the working units' estimate after the Step (NaN otherwise, and
  // when a replacing hook decides).
  std::vector<double> estimated_working;
};

// A hook at the control instants of RunTask. Replaces() false: OnInstant sees what the task's
// controllers decided (a recorder). True: OnInstant decides in their place, filling every
// decided field (e.g. an exported controller under test, tests/export); hand-set and force
// tasks only (not "outer_loop": "auto").
class ControlInstantHook {
 public:
  virtual ~ControlInstantHook() = default;
  virtual bool Replaces() const = 0;
  virtual Status OnInstant(ControlInstant& instant) = 0;
};

// Settings of one run. Unset optionals keep the task file's values.
struct RunOptions {
  std::optional<std::string> estimator;     // "output", "kalman", ...
  std::optional<std::string> filter_model;  // filter model file for "kalman"
  std::optional<double> dT;                 // s
  std::optional<double> lambda;
  std::optional<double> force_noise_std;  // N, Kalman estimators' measurement noise
  std::optional<double> duration;         // s
  std::uint64_t seed = 1;
  bool progress = false;  // progress on stderr
  // kalman-augmented without a model file, and the self-tuned loop's design: identify (and
  // cache, identification/model_cache.h) a model missing from the search path for the bundle and
  // dT. Off (an error naming the command that makes one) unless the caller turns it on: the
  // `recruit` commands and the Python package do; a library user decides.
  bool identify_missing_models = false;
  bool quiet = false;  // no notes on stderr (e.g. that a model is being identified)
  ControlInstantHook* control_hook = nullptr;  // not owned; null: none
};

// One bundle's scores: its estimate against the ground-truth count at the control instants, and
// its units' peaks against the datasheet limits of its wire (SmaBundle::limits()).
struct BundleSummary {
  std::string actuator;
  double estimator_rmse = 0;     // units
  double mean_nees = 0;          // NaN: the estimator gives no variance
  double estimator_within3 = 0;  // fraction of control instants with |n^ - n| <= 3
  // The same within max(3, 5 % of the bundle's units): "within 3 units, or 5 % of N for a bundle
  // of many units".
  double estimator_band = 3;         // units
  double estimator_within_band = 0;  // fraction of control instants
  double peak_temperature = 0;       // C, hottest unit over the run
  double peak_wire_stress = 0;       // Pa, most stressed wire over the run
  double max_temperature = 0;        // C, the limit
  double max_wire_stress = 0;        // Pa, the limit
  // With a census (controller.census_period > 0): the censuses whose counts reached the
  // controller. Unset (and not in the JSON) without one.
  std::optional<long> censuses;
};

// One driven joint's scores (self-tuned angle tasks).
struct JointSummary {
  std::string joint;
  double tracking_rmse = 0;  // rad
  double iae = 0;            // rad s
  double max_overshoot = 0;  // fraction of the step
  double settled_fraction = 0;
  int num_steps = 0;
};

struct RunSummary {
  std::string task;
  std::string estimator;
  double dT = 0, lambda = 0;
  std::uint64_t seed = 0;
  double duration = 0;                // simulated s
  double wall_seconds = 0;            // s, the run itself (identification left out)
  double identification_seconds = 0;  // s spent identifying filter models before the run
  long physics_steps = 0;
  long control_instants = 0;
  std::string unit;                    // "N" or "rad"
  RunMetrics metrics;                  // estimator scores here are the agonist's
  std::vector<BundleSummary> bundles;  // every bundle (agonist first)
  SensorParams sensor;                 // the load cell the controllers read
  std::vector<std::string> warnings;   // limits exceeded, also printed on stderr
  std::vector<StepResponse> steps;
  std::vector<std::string> step_joints;  // the joint of each step (several-joint tasks)
  // The tracked signal's response to each push (the steps are scored up to a push).
  std::vector<DisturbanceResponse> pushes;
  std::vector<JointSummary> joints;  // self-tuned angle tasks: per driven joint
  nlohmann::json loop_designs;       // self-tuned angle tasks: each design made (JSON)

  nlohmann::json ToJson() const;
  // True if a bundle's hottest unit or most stressed wire passed its wire's datasheet limit.
  bool PastDatasheetLimits() const {
    for (const BundleSummary& b : bundles) {
      if (b.peak_temperature > b.max_temperature || b.peak_wire_stress > b.max_wire_stress) {
        return true;
      }
    }
    return false;
  }
};

// The effective settings after applying `options` to the task's defaults.
ControllerSettings EffectiveSettings(const Task& task, const RunOptions& options);

// The self-tuned loop's designs for a task (`recruit tune-loop`): for each driven joint, at the
// pose of every reference value it steps to (the other joints at their references then), the
// model it was designed on, the gains and the predicted step response. Angle tasks with
// "outer_loop": "auto" only.
struct JointDesignRecord;
Result<std::vector<JointDesignRecord>> DesignTaskLoops(const Task& task, const RunOptions& options);

// One bundle's controller as RunTask builds it for a task (the estimator on the bundle's model,
// the length-aware target), reset to its initial belief.
struct BundleController {
  std::string actuator;
  control::RecruitmentController controller;
};
// Every bundle's (agonist first): what `recruit export` writes as C.
Result<std::vector<BundleController>> TaskControllers(const Task& task, const RunOptions& options);

Result<RunSummary> RunTask(const Task& task, const RunOptions& options,
                           const std::vector<StepObserver*>& observers = {});

}  // namespace recruit::sim
