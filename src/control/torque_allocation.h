// Torque allocation: the tensions of the bundles that cross a limb's joints, chosen so that their
// torques meet each joint's demand. A bundle only pulls (tension >= 0) and has a co-contraction
// floor and a capacity (all its units on, at the tendon's present length); a biarticular bundle
// acts on both of its joints. docs/controller.md, "Several bundles and joints".
#pragma once

#include <Eigen/Core>

namespace recruit::control {

struct AllocationProblem {
  // joints x bundles: the torque (N m) on joint j per newton of bundle b's tension, at the
  // present pose (MuJoCo's actuator moment arm, sign included).
  Eigen::MatrixXd arms;
  Eigen::VectorXd torque;  // per joint, N m: the demand
  // per bundle, N: least tension (co-contraction), 0 <= floor <= cap; a bundle whose floor is
  // its cap is held there (its tension is given, the others share what it leaves).
  Eigen::VectorXd floor;
  Eigen::VectorXd cap;  // per bundle, N: capacity, > 0
  // per bundle, > 0 (empty: all 1): the price of its share; a slower bundle priced higher is
  // left the smaller share of a demand the others can meet.
  Eigen::VectorXd price;
};

// Minimizes  sum_j ((arms T - torque)_j / s_j)^2 + eps sum_b (price_b T_b / cap_b)^2
// subject to floor <= T <= cap, with s_j = sum_b |arms_jb| cap_b (joint j's torque span; a joint
// no bundle moves is left out). The first term meets the demands where the bundles can; the
// small second one shares a joint's demand among the bundles that cross it in proportion to
// their moment arms and the square of their capacities over their prices, and makes the
// solution unique.
// A primal active-set method for the box-constrained quadratic (finite; exact to rounding): the
// problem is strictly convex, so its one minimum does not depend on where the search starts.
Eigen::VectorXd AllocateTensions(const AllocationProblem& p, double eps = 1e-8);

// The tensions as whole numbers of on units: bundle b pulls `unit_force[b]` (N) per unit on, so
// a controller can hold only multiples of it. Among the counts near each bundle's continuous
// count (from one below its floor to one above its ceiling for up to four bundles, floor or
// ceiling beyond that; never below 0 or above `units[b]`), the combination with the least cost
// above. A limb's bundles with different unit forces then resolve the demand more finely than
// any one of them: the self-tuned loop's residual error is not one unit's worth.
Eigen::VectorXd RoundToUnits(const AllocationProblem& p, const Eigen::VectorXd& tensions,
                             const Eigen::VectorXd& unit_force, const Eigen::VectorXi& units,
                             double eps = 1e-8);

// The objective above, for tests and reports.
double AllocationCost(const AllocationProblem& p, const Eigen::VectorXd& tensions,
                      double eps = 1e-8);

}  // namespace recruit::control
