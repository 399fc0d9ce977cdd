// TransientChain: the augmented discrete model of one SMA unit's heating and cooling transient
// (the paper's Figs. 6-8), with the topology `recruit identify` fits. docs/identification.md.
//
// m = 2K + 2 states, in this order:
//   0            "cold"     heater off, settled at ambient
//   1 .. K       "heat<i>"  heater on, i-th heating state (entered on switch-on)
//   K + 1        "hot"      heater on, settled
//   K + 2 .. 2K+1 "cool<i>" heater off, i-th cooling state (entered on switch-off)
// Interior (no switching) edges, per sampling period dT: heat<i> advances to the next heating
// state (heat<K> to hot) with probability heat_advance[i-1] and otherwise stays; cool<i>
// likewise towards cold with cool_advance[i-1]; cold and hot stay.
// Switching edges: a unit in an off state switched on lands, one dT later, on switch_on[state]
// (a heating state or hot); a unit in an on state switched off lands on switch_off[state] (a
// cooling state or cold). cold -> heat1 and hot -> cool1 are fixed (the step responses); the
// targets of the mid-transient states are fitted (`recruit identify` starts from the heat level
// below and moves each target to the state of the other chain that fits the data best).
// The heat level L: cold 0, heat<i> i, hot K + 1, cool<i> K + 1 - i; switching on from level L
// lands on the heating state of level min(L + 1, K + 1), switching off on the cooling state of
// level max(L - 1, 0).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace recruit::identification {

struct TransientChain {
  int chain_length = 9;          // K (m = 2K + 2; K = 9 gives the paper's 20 states)
  Eigen::VectorXd heat_advance;  // K entries in [0, 1]
  Eigen::VectorXd cool_advance;  // K entries in [0, 1]
  Eigen::VectorXd force;         // H: m entries, N per unit in each state
  // Switching targets per state, -1 where the switch does not apply (switch_on of an on state,
  // switch_off of an off state).
  std::vector<int> switch_on, switch_off;

  // K = num_states / 2 - 1, every advance probability `advance`, force zero, switching
  // targets by heat level.
  static TransientChain Uniform(int num_states, double advance);

  int num_states() const { return 2 * chain_length + 2; }
  int cold() const { return 0; }
  int heat(int i) const { return i; }  // i = 1..K
  int hot() const { return chain_length + 1; }
  int cool(int i) const { return chain_length + 1 + i; }  // i = 1..K

  std::vector<std::string> StateNames() const;
  std::vector<bool> IsOn() const;  // heater command per state
  int Level(int state) const;      // heat level, 0 .. K + 1
  // The heat-level targets (-1 where a switch does not apply).
  std::vector<int> LevelOnTarget() const;
  std::vector<int> LevelOffTarget() const;
  // Next state along the state's chain (heat<K> -> hot, cool<K> -> cold); -1 for cold and hot.
  int Next(int state) const;
  // Column-stochastic interior matrix (m x m).
  Eigen::MatrixXd Interior() const;
  // A(p_on, p_off) = per column (1 - p) interior + p e_target (the estimation contract).
  Eigen::MatrixXd Matrix(double p_on, double p_off) const;
  // x <- A(p_on, p_off) x in O(m), without forming A.
  void PropagateMean(double p_on, double p_off, Eigen::VectorXd& x) const;
  // Qz(x) = diag(A x) - A diag(x) A^T (eq. 25), the covariance the transitions add.
  Eigen::MatrixXd TransitionCovariance(double p_on, double p_off, const Eigen::VectorXd& x) const;
};

}  // namespace recruit::identification
