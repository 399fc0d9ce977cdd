// How much each state of a broadcast chain counts as "in transit" in the measurement noise
// R(x) = R + n R_transit + n^2 R_transit2, n = w . max(x, 0) (docs/identification.md, "Noise in
// transit"). The noise in transit is the chain's error in when a unit moves on: a unit that is
// one period early or late is off by the force between its state and the next. So a state's
// weight is that force step, |H(next) - H(state)|, as a fraction of the output's whole range
// (largest over the outputs); next is the state the unit most likely moves to. Settled states
// (interior(j, j) = 1) weigh 0; a transit state whose force is already its successor's (the tail
// of a transient) weighs about 0, so a population that has all but settled is trusted again.
#pragma once

#include <Eigen/Dense>

namespace recruit::estimation {

// interior: m x m column-stochastic (column j: where a unit in state j goes without a switch);
// H: r x m output map. Returns m weights in [0, 1].
Eigen::VectorXd TransitWeights(const Eigen::MatrixXd& interior, const Eigen::MatrixXd& H);

}  // namespace recruit::estimation
