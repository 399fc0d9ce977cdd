// Plant: the MuJoCo side of a task, what a lab's rig would be. The limb model with its SMA
// bundles (the task's agonist and antagonist), the tracked joint, the payload changes and pushes
// the task schedules, and the peaks of each bundle's units against their datasheet limits.
// The controller side (load cells, estimators, recruitment controllers, the outer loop) only
// reads it (forces, tendon lengths, the joint) and broadcasts to its bundles.
#pragma once

#include <mujoco/mujoco.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/mujoco_ptr.h"
#include "common/result.h"
#include "plugin/sma_host.h"
#include "sim/task.h"

namespace recruit::sim {

class Plant {
 public:
  // Loads task.model_path (timestep overridden by task.timestep when > 0) and finds the task's
  // bundles, joint and bodies; errors name the task file's field. Without `drawn` (nothing
  // will draw the model) its builtin textures are made 1 pixel, and its cameras and lights, the
  // world's geoms no contact reaches and the sites nothing names are left out (what a sensor,
  // a tendon, an actuator, a pair, an equality or a custom tuple names stays); the physics is
  // the same.
  static Result<std::unique_ptr<Plant>> Create(const Task& task, bool drawn = true);

  // Every unit off and cold (the units' streams seeded by `seed`), the model at rest, forces
  // computed; the payloads due at t = 0 applied.
  void Reset(std::uint64_t seed);
  // The disturbances due at the current time (payload changes, pushes), then one physics step
  // (without MuJoCo's constraint stage when it can make no row: the step is the same).
  void Step();
  // After a step: a NaN in qpos is an error naming the time (the simulation diverged). Inline,
  // and the error made out of line: it runs after every step (a call was ~35 instructions a step).
  Status CheckFinite() const {
    for (int k = 0; k < model_->nq; ++k) {
      if (!std::isfinite(data_->qpos[k])) return Diverged();
    }
    return Status::Ok();
  }

  // True if steps clear of every joint limit skip MuJoCo's constraint stage (Step), and how many
  // steps since Create did.
  bool skips_constraints_off_limits() const { return gate_.has_value(); }
  long constraint_stages_skipped() const { return skipped_; }
  const mjModel* model() const { return model_.get(); }
  mjData* data() const { return data_.get(); }
  const sma::SmaHost& host() const { return *host_; }
  double time() const { return data_->time; }
  double timestep() const { return model_->opt.timestep; }

  // Bundles: 0 the agonist, 1 the antagonist (when the task has one).
  int num_bundles() const { return static_cast<int>(bundles_.size()); }
  int bundle_index(int i) const { return bundles_[i]; }  // in the host
  const std::string& bundle_name(int i) const { return host_->bundle_name(bundles_[i]); }
  int num_units(int i) const { return host_->num_units(bundles_[i]); }
  double Force(int i) const { return BundleTelemetry(i).tension; }  // exact, N
  // Bundle i's length coordinate (gear x tendon length, SmaHost::UnitLength): what the joint
  // encoders give the controller, and the length its unit force map reads.
  double UnitLength(int i) const { return host_->UnitLength(data_.get(), bundles_[i]); }
  int OnCount(int i) const { return BundleTelemetry(i).on_count; }
  double MeanTemperature(int i) const { return BundleTelemetry(i).mean_temperature; }  // C
  Status Broadcast(int i, double p_on, double p_off) {
    telemetry_valid_[i] = false;  // the units' states change
    return host_->Broadcast(data_.get(), bundles_[i], p_on, p_off);
  }

  // The tracked joint (a hinge), when the task names one.
  bool has_joint() const { return qadr_ >= 0; }
  double angle() const { return qadr_ >= 0 ? data_->qpos[qadr_] : 0.0; }
  double angular_velocity() const { return dadr_ >= 0 ? data_->qvel[dadr_] : 0.0; }

  // The driven joints of a self-tuned angle task (Task::joints), in the task's order.
  int num_joints() const { return static_cast<int>(joints_.size()); }
  const std::string& joint_name(int j) const { return task_->joints[j].joint; }
  double JointAngle(int j) const { return data_->qpos[model_->jnt_qposadr[joints_[j]]]; }
  double JointVelocity(int j) const { return data_->qvel[model_->jnt_dofadr[joints_[j]]]; }
  // joints x bundles: the torque (N m) on driven joint j per newton of bundle i's tension at
  // the pose of the last step (MuJoCo's actuator moment; a bundle pulls, so minus the moment).
  Eigen::MatrixXd MomentArms() const;
  // The same with the driven joints at `q` (the others where they are now), and each bundle's
  // length coordinate (UnitLength) there: what the loop design linearises about.
  Eigen::MatrixXd MomentArmsAt(const Eigen::VectorXd& q) const;
  Eigen::VectorXd UnitLengthsAt(const Eigen::VectorXd& q) const;
  // The torque each driven joint needs to hold the limb still with the driven joints at `q`
  // (the others where they are now): gravity, payloads and springs, from MuJoCo's inverse
  // dynamics with zero velocity and acceleration and no constraint rows.
  Eigen::VectorXd StaticTorque(const Eigen::VectorXd& q) const;
  // Driven joint j's inertia (mass-matrix diagonal, armature included) with the driven joints at
  // `q`.
  double JointInertia(int j, const Eigen::VectorXd& q) const;
  // Driven joint j's range, when it is limited.
  bool JointRange(int j, double* lo, double* hi) const {
    if (!model_->jnt_limited[joints_[j]]) return false;
    *lo = model_->jnt_range[2 * joints_[j]];
    *hi = model_->jnt_range[2 * joints_[j] + 1];
    return true;
  }
  // Driven joint j's viscous damping with the driven joints at `q`: its own, and the tendons' and
  // actuators' (the bundles' dampers) through their moment arms there (sma::JointDamping).
  double JointDamping(int j, const Eigen::VectorXd& q) const;
  // The limb's position at `q`, velocities zero, on the scratch data (for StaticTorque).
  void PoseScratch(const Eigen::VectorXd& q) const;

  // Hottest unit and most stressed wire of bundle i since Reset.
  double peak_temperature(int i) const { return peak_temperature_[i]; }
  double peak_wire_stress(int i) const { return peak_stress_[i]; }

 private:
  Plant() = default;
  Eigen::MatrixXd MomentArmsOf(const mjData* d) const;
  void PoseTransmission(const Eigen::VectorXd& q) const;  // scratch: tendons, moments at q
  Status FindBundles(const Task& task, const std::string& where);
  Status FindJoints(const Task& task, const std::string& where);
  Status Diverged() const;  // CheckFinite's error
  void ApplyPayloads();
  void ApplyPushes();
  void TrackPeaks();  // reads every bundle's telemetry afresh (after a step or a reset)
  // Bundle i's units as they are now (force, on count, temperatures, stress): one pass over its
  // cohorts after each step or broadcast, bit for bit what the separate reads give. A run reads
  // them several times a step (measurement, telemetry, peaks): one pass, ~280 instructions for
  // 60 units (callgrind, arm_push), instead of four.
  // The kept pass is read inline; only a new pass is a call.
  const sma::SmaBundle::Telemetry& BundleTelemetry(int i) const {
    return telemetry_valid_[i] ? telemetry_[i] : ReadBundleTelemetry(i);
  }
  const sma::SmaBundle::Telemetry& ReadBundleTelemetry(int i) const;
  void ForgetTelemetry() { telemetry_valid_.assign(bundles_.size(), false); }

  const Task* task_ = nullptr;
  // The plant's own copy of the task's model (Create loads it; it is never shared, and model()
  // hands out a const view). It is changed in these places only, each because MuJoCo keeps the
  // setting in mjModel and nowhere else:
  //  - Create: task.timestep, and the stages the model has nothing for disabled (sensors,
  //    friction loss, equality, islands; mjOption is part of mjModel);
  //  - Step and StaticTorque: the constraint stage switched off for one call and restored
  //    (DisableForOneCall in plant.cc), as stage switches exist only in mjModel.opt;
  //  - ApplyPayloads: a payload body's mass and inertia (MuJoCo has no per-mjData mass); Reset
  //    restores them from body_mass0_ and body_inertia0_, so runs from a Reset are alike.
  ModelPtr model_;
  DataPtr data_;
  std::unique_ptr<sma::SmaHost> host_;
  std::vector<int> bundles_;
  int qadr_ = -1, dadr_ = -1;
  std::vector<int> joints_;  // driven joints' ids (self-tuned angle tasks)
  DataPtr scratch_;          // for the inverse dynamics of StaticTorque and JointInertia
  std::vector<int> push_body_, payload_body_;
  std::vector<bool> payload_done_;
  size_t payloads_pending_ = 0;  // payload changes not yet applied
  bool pushed_ = false;          // a push was active at the last ApplyPushes
  // The joints a step must start clear of to skip the constraint stage; none if it never does.
  std::optional<std::vector<int>> gate_;
  long skipped_ = 0;
  std::vector<double> peak_temperature_, peak_stress_;
  mutable std::vector<sma::SmaBundle::Telemetry> telemetry_;  // a cache: see BundleTelemetry
  mutable std::vector<unsigned char> telemetry_valid_;
  // Each payload body's mass and inertia as loaded (Reset restores them).
  std::vector<double> body_mass0_, body_inertia0_;
};

}  // namespace recruit::sim
