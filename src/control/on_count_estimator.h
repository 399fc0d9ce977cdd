// On-count estimators: how many units of a bundle have their heater on, from the bundle's force.
//
// One estimator per bundle, called once per sampling period dT, in this order at each control
// instant k:
//   UpdateWithMeasurement(y_k, L_k)  update with the force and the tendon length sampled at instant
//   k (before
//                      broadcasting); L_k NaN = not measured (the model's reference length)
//   EstimatedOn()      the a-posteriori on-count at instant k, which the law uses
//   Broadcasted(b_k)   the broadcast just sent: predict to instant k + 1
// Kinds (docs/controller.md):
//   "output"            count = force / settled force of one unit (the paper's failing baseline)
//   "kalman2"           population Kalman filter on the two-state (off/on) model
//   "kalman-augmented"  population Kalman filter on the identified transient model
//                       (models/identified/, `recruit identify`); "on" = the states whose heater
//                       is on (heating chain and hot settled state)
//   "kalman-failures"   kalman-augmented with absorbing open/stuck states and declared failures
//                       (estimation/failure_filter.h): also estimates the working units
#pragma once

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "common/result.h"
#include "control/broadcast.h"
#include "control/unit_force_map.h"
#include "estimation/failure_filter.h"
#include "estimation/population_kalman_filter.h"

namespace recruit::control {

// What a failure-aware estimator knows of a bundle's failed units (docs/failures.md).
struct FailureEstimate {
  double working = 0, open = 0, stuck = 0;  // units (estimates; they add to N)
  double working_variance = 0;              // units^2
  int declarations = 0;                     // failures declared since Reset
  bool declared = false;                    // the last UpdateWithMeasurement declared one
  double force_scale = 1;                   // working units' fatigue force scale
  // How strongly the innovations suggest an undeclared loss: the failure test's largest
  // log-likelihood ratio at the last update (0 when none, and right after a declaration).
  double suspicion = 0;
};

class OnCountEstimator {
 public:
  virtual ~OnCountEstimator() = default;
  // Back to the initial belief: every unit off, at ambient (cold settled state).
  virtual void Reset() = 0;
  // The force (N) and the tendon length (m, from the joint encoder; NaN when not measured)
  // sampled at this control instant. A length-aware estimator (built with a UnitGeometry) takes
  // each state's unit force at that length; without one, at the model's reference length.
  virtual void UpdateWithMeasurement(double measured_force, double tendon_length) = 0;
  void UpdateWithMeasurement(double measured_force) {
    UpdateWithMeasurement(measured_force, std::numeric_limits<double>::quiet_NaN());
  }
  // The broadcast just sent at this instant: predict to the next instant (dT later).
  virtual void Broadcasted(const Broadcast& b) = 0;
  // Units whose heater is on.
  virtual double EstimatedOn() const = 0;
  // Variance of EstimatedOn(), units^2; NaN when the estimator has none (output only).
  virtual double EstimatedOnVariance() const = 0;
  // Counts per model state (entries named by StateNames()), for NEES and RMSE.
  virtual Eigen::VectorXd StateEstimate() const = 0;
  virtual std::vector<std::string> StateNames() const = 0;
  // Which model states count as "on" (heater on); same length as StateNames().
  virtual std::vector<bool> OnStates() const = 0;
  // The failed units' estimate; none from estimators that assume every unit works.
  virtual std::optional<FailureEstimate> Failures() const { return std::nullopt; }
};

// The estimator kinds, named "output", "kalman2", "kalman-augmented" in task files, sweeps and
// on the command line (ParseEstimatorKind, EstimatorKindName).
enum class EstimatorKind { kOutput, kKalman2, kKalmanAugmented };
Result<EstimatorKind> ParseEstimatorKind(const std::string& name);
const char* EstimatorKindName(EstimatorKind kind);

// What estimator to build: the one typed value the task file, the command line and a sweep all
// produce (Parse / FromJson validate the names and values).
struct EstimatorSpec {
  EstimatorKind kind = EstimatorKind::kKalmanAugmented;
  estimation::CovarianceMode covariance = estimation::CovarianceMode::kExtended;  // Kalman kinds
  // kalman-augmented: the FilterModel file. Empty: DefaultModelFile(dT, num_states).
  std::string model_file;
  int num_states = 20;  // kalman-augmented: states of the model (checked against the file)
  // Force measurement noise standard deviation, N. <= 0: the default, which is the model file's
  // R for kalman-augmented and one settled unit's force for kalman2 (the two-state model's error
  // while units are in transient is of that size).
  double force_noise_std = 0;
  // Variance of the load cell's reading (noise and quantisation), N^2, added to the model's R
  // (which is what the unit population and the model's error add, from identification).
  double sensor_variance = 0;
  // kalman-augmented with absorbing failed states (FailureKalmanFilter): the kind name
  // "kalman-failures" sets it; `failure` holds the filter's detection settings.
  bool failures = false;
  estimation::FailureFilterParams failure;
  // kalman-augmented: the plant the model will run on (control/plant_record.h, PlantRecord);
  // null = unchecked. A model file recording another plant is refused (CheckModelPlant).
  nlohmann::json plant;

  static Result<EstimatorSpec> Parse(const std::string& kind,
                                     const std::string& covariance = "extended",
                                     const std::string& model_file = "", int num_states = 20,
                                     double force_noise_std = 0);
  // {"kind": ..., "covariance": ..., "model_file": ..., "num_states": ..., "force_noise_std": ...}
  // (all optional); `where` names the file for error messages.
  static Result<EstimatorSpec> FromJson(const nlohmann::json& j, const std::string& where);
};

// The identified model shipped for a sampling period, e.g.
// "models/identified/bench_n60_dt0.5_m20.json".
std::string DefaultModelFile(double dT, int num_states);

// Builds the estimator for a bundle of `num_units` units whose settled on-force is `unit_force`
// (N, at the reference length), sampled every `dT` seconds. A kalman-augmented model identified
// for another N is rescaled to num_units (the per-unit model does not depend on N); its dt must
// equal dT. With `geometry` the estimator is length-aware (UnitForceMap): each state's force
// follows the measured tendon length.
Result<std::unique_ptr<OnCountEstimator>> MakeEstimator(const EstimatorSpec& spec, int num_units,
                                                        double unit_force, double dT,
                                                        const UnitGeometry* geometry = nullptr);

}  // namespace recruit::control
