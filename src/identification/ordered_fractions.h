// The order of a transient chain's martensite fractions (docs/identification.md, "On a limb"):
// a unit heating transforms to austenite (its fraction falls) along cold, heat1.., hot and back
// along hot, cool1.., cold; the force, which falls with the fraction, keeps the order the fit
// gives H (identification.h, FitOptions::monotone).
#pragma once

#include <Eigen/Core>

#include "identification/transient_chain.h"

namespace recruit::identification {

// The fractions xi + step nearest in the metric M, i.e. minimising step^T M step / 2 + g^T step,
// among those in the order with cold and hot kept where xi has them: every state between them,
// falling along the heating path and rising along the cooling path. M symmetric positive
// definite on the other states. A quadratic programme in the falls and rises (>= 0; each path's
// sum closed by a penalty), solved exactly by NonNegativeQp. With M = I and g = 0: the
// Euclidean projection of xi onto the order.
Eigen::VectorXd OrderedFractions(const TransientChain& chain, const Eigen::VectorXd& xi,
                                 const Eigen::MatrixXd& M, const Eigen::VectorXd& g);

// The largest step of `xi` against that order (0 when in order).
double FractionOrderViolation(const TransientChain& chain, const Eigen::VectorXd& xi);

}  // namespace recruit::identification
