// The filter model file (docs/formats/filter.md): what a population filter needs to know about
// the units and the sensor. `recruit identify` writes it, `recruit filter` and the controller
// read it.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <limits>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <utility>
#include <vector>

#include "common/result.h"
#include "estimation/broadcast_transition_model.h"

namespace recruit::estimation {

// Where A(t) comes from.
enum class TransitionSource {
  kBroadcast,  // A(t) = broadcast.Matrix(p_on(t), p_off(t)), inputs per step
  kExplicit,   // A(t) given entry by entry at every step (the log's A_i_j columns)
  kConstant,   // one A for every step (`A` below)
};

struct FilterModel {
  std::vector<std::string> state_names;  // m names, unique
  int64_t N = 0;                         // agents (units), >= 1
  Eigen::MatrixXd H;                     // r x m output matrix, y = H X + v (eq. 12)
  Eigen::MatrixXd R;                     // r x r measurement noise covariance, SPD
  // r x r, symmetric PSD (default 0): the measurement noise the units in transit add, so that
  // the covariance at a predicted state x is R + n R_transit + n^2 R_transit2, n = TransitCount(x)
  // (kBroadcast only). R_transit: independent errors per unit; R_transit2: an error the units in
  // transit share (units switched together follow one deterministic transient).
  Eigen::MatrixXd R_transit;
  Eigen::MatrixXd R_transit2;
  Eigen::MatrixXd G;   // m x q process noise input (q may be 0)
  Eigen::MatrixXd Qw;  // q x q process noise covariance, PSD
  TransitionSource transition = TransitionSource::kBroadcast;
  BroadcastTransitionModel broadcast;  // kBroadcast
  Eigen::MatrixXd A;                   // kConstant: m x m column-stochastic
  Eigen::VectorXd x0;                  // initial estimate, sums to N (default: all in state 0)
  Eigen::MatrixXd P0;                  // initial covariance (default 0: x0 known exactly)
  // Read only: the R^2 of the force held out of the identification (identification.holdout.r2)
  // when the file records one; NaN otherwise.
  double holdout_r2 = std::numeric_limits<double>::quiet_NaN();

  int num_states() const { return static_cast<int>(state_names.size()); }
  int num_outputs() const { return static_cast<int>(H.rows()); }
  // G Qw G^T (m x m); zero when q = 0.
  Eigen::MatrixXd ProcessNoise() const;
  // True when R_transit or R_transit2 is not all zero (the measurement noise depends on the state).
  bool has_transit_noise() const { return NonZero(R_transit) || NonZero(R_transit2); }
  // How much each state counts as in transit (estimation/transit_weights.h): for the states a
  // unit leaves without being switched (interior(j, j) < 1 in the broadcast model: the heating
  // and cooling transients), the force step to the next state over H's range; 0 for the settled
  // states and for other transition sources.
  Eigen::VectorXd TransitWeights() const;

  // Checks every field and the relations between them; `where` (the file) prefixes messages.
  // G Qw G^T must have zero column sums: process noise cannot change the total N.
  Status Validate(const std::string& where = "filter model") const;

  static bool NonZero(const Eigen::MatrixXd& m) { return m.size() > 0 && (m.array() != 0).any(); }
  // A one-output model's transit coefficients, R_transit(0, 0) and R_transit2(0, 0), 0 for a
  // missing matrix: its transit noise is n first + n^2 second.
  std::pair<double, double> ScalarTransitNoise() const {
    auto entry = [](const Eigen::MatrixXd& t) { return t.size() > 0 ? t(0, 0) : 0.0; };
    return {entry(R_transit), entry(R_transit2)};
  }

  // The same units and sensor for a population of N agents: x0 and P0 are rescaled by N'/N.
  FilterModel WithPopulation(int64_t N_new) const;

  static Result<FilterModel> FromJson(const std::string& path);
  static Result<FilterModel> FromJsonValue(const nlohmann::json& j,
                                           const std::string& where = "filter model");
  nlohmann::json ToJson() const;
  // Written atomically (AtomicFile): a failed save leaves any previous file untouched.
  Status Save(const std::string& path) const;

  // The two-state (off/on) model with a force sensor: H = [0, unit_force], R = noise_std^2.
  static FilterModel TwoState(int64_t N, double dt, double unit_force, double noise_std);
};

}  // namespace recruit::estimation
