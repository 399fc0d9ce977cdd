// The broadcast transition model: the transition matrix A(p_on, p_off) that a broadcast of the
// on/off probabilities induces on one unit's state over one sampling period dt.
#pragma once

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "common/result.h"

namespace recruit::estimation {

// Column j (a unit in state j) of A(p_on, p_off) is
//   (1 - p) * interior(:, j) + p * e_{target}
// with p = p_on and target = on_target[j] when state j is an "off" state (is_on[j] false), and
// p = p_off and target = off_target[j] when it is an "on" state. `interior` is what a unit does
// over dt when the broadcast does not switch it (column-stochastic). Unused target entries (the
// on_target of an on state, the off_target of an off state) are -1.
// The two-state model is interior = I, is_on = {false, true}, on_target = {1, -1},
// off_target = {-1, 0}: A = [[1 - p_on, p_off], [p_on, 1 - p_off]].
struct BroadcastTransitionModel {
  std::vector<std::string> state_names;
  std::vector<bool> is_on;   // the unit's heater command in each state
  Eigen::MatrixXd interior;  // column-stochastic, m x m
  std::vector<int> on_target, off_target;
  double dt = 0.0;  // s, the sampling period it was identified for

  int num_states() const { return static_cast<int>(state_names.size()); }

  // A(p_on, p_off); p_on, p_off in [0, 1] (see ValidateInputs). Column-stochastic by
  // construction when the model is valid.
  Eigen::MatrixXd Matrix(double p_on, double p_off) const;
  // The same into a caller-owned m x m matrix (no allocation; for the fixed-size filters).
  template <class Derived>
  void FillMatrix(double p_on, double p_off, Eigen::MatrixBase<Derived>& A) const {
    const int m = num_states();
    for (int j = 0; j < m; ++j) {
      const double p = is_on[j] ? p_off : p_on;
      const int target = is_on[j] ? off_target[j] : on_target[j];
      for (int i = 0; i < m; ++i) A(i, j) = (1.0 - p) * interior(i, j);
      A(target, j) += p;
    }
  }

  // The sparsity pattern of A(p_on, p_off) for every (p_on, p_off): the nonzeros of `interior`
  // and each column's switch target; values those of A(0, 0). Build once, then FillSparse.
  Eigen::SparseMatrix<double> SparsePattern() const;
  // Writes the values of A(p_on, p_off) into a matrix with the structure SparsePattern()
  // returned (no allocation; for PopulationKalmanFilterT::Predict's sparse overload).
  void FillSparse(double p_on, double p_off, Eigen::SparseMatrix<double>& A) const {
    for (int j = 0; j < A.outerSize(); ++j) {
      const double p = is_on[j] ? p_off : p_on;
      const int target = is_on[j] ? off_target[j] : on_target[j];
      for (Eigen::SparseMatrix<double>::InnerIterator it(A, j); it; ++it) {
        const int i = static_cast<int>(it.row());
        it.valueRef() = (1.0 - p) * interior(i, j) + (i == target ? p : 0.0);
      }
    }
  }

  static BroadcastTransitionModel TwoState(double dt);
  // A generic m-state heating / cooling chain (m >= 2), the shape of the identified SMA models:
  // state 0 is off and settled; states 1..h (h = m / 2) are on, a unit moving one state up per
  // step with probability 1/2 (h settled); states h+1..m-1 are off and cooling, one state on
  // per step with probability 1/2, the last one back to 0. p_on sends an off state to 1; p_off
  // sends on state i to the cooling state of the same temperature. At most 3 nonzeros per
  // column of A (benchmarks and tests of the sparse filter for any m).
  static BroadcastTransitionModel HeatingChain(int m, double dt);

  // Checks sizes, names, interior (column-stochastic), targets in range, dt > 0.
  // `where` prefixes messages, e.g. "model.json: transition".
  Status Validate(const std::string& where = "broadcast transition model") const;
  // p_on and p_off finite and in [0, 1].
  static Status ValidateInputs(double p_on, double p_off, const std::string& where = "broadcast");

  // {"type": "broadcast", "dt": .., "is_on": [..], "interior": [[..]..] (row-major, m rows),
  //  "on_target": [..], "off_target": [..]}; state names come from the enclosing model.
  // "interior" may be omitted for the identity; a target may be a single integer for all states.
  static Result<BroadcastTransitionModel> FromJsonValue(const nlohmann::json& j,
                                                        const std::vector<std::string>& names,
                                                        const std::string& where);
  nlohmann::json ToJson() const;
};

}  // namespace recruit::estimation
