// Convex quadratic programme with sign constraints, in normal form:
//   min over z of 0.5 z^T Q z - c^T z   subject to z_i >= 0 where free[i] is false,
// Q symmetric positive definite. The active-set method of Lawson and Hanson ("Solving Least
// Squares Problems", 1974, ch. 23) on the normal equations (Bro and De Jong, J. Chemometrics
// 11, 1997), with the free variables kept in the passive set from the start. Exact in finitely
// many steps; the result satisfies the KKT conditions to rounding.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace recruit::identification {

// `free` has c.size() entries (empty: every variable constrained).
Eigen::VectorXd NonNegativeQp(const Eigen::MatrixXd& Q, const Eigen::VectorXd& c,
                              const std::vector<bool>& free = {});

}  // namespace recruit::identification
