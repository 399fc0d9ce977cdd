// AllocateTensions against an exhaustive solver: every assignment of each bundle to its floor,
// its capacity or free (3^n), the free ones from the equality-constrained least squares, the
// feasible one with the least cost (the KKT point of a strictly convex problem is its minimum).
#include "control/torque_allocation.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <random>

namespace recruit::control {
namespace file_torque_allocation_test {

Eigen::VectorXd Exhaustive(const AllocationProblem& p, double eps) {
  const int n = static_cast<int>(p.cap.size());
  Eigen::VectorXd best;
  double best_cost = std::numeric_limits<double>::infinity();
  int combos = 1;
  for (int i = 0; i < n; ++i) combos *= 3;
  for (int c = 0; c < combos; ++c) {
    Eigen::VectorXd x(n);
    std::vector<int> free;
    for (int i = 0, code = c; i < n; ++i, code /= 3) {
      if (code % 3 == 0) x[i] = p.floor[i];
      if (code % 3 == 1) x[i] = p.cap[i];
      if (code % 3 == 2) free.push_back(i);
    }
    if (!free.empty()) {
      // Minimise the cost over the free variables: a least-squares problem in closed form.
      Eigen::VectorXd w(p.arms.rows());
      for (int j = 0; j < p.arms.rows(); ++j) {
        const double span = p.arms.row(j).cwiseAbs().dot(p.cap);
        w[j] = span > 0 ? 1 / span : 0;
      }
      const int nf = static_cast<int>(free.size());
      Eigen::MatrixXd a(p.arms.rows() + nf, nf);
      Eigen::VectorXd rhs(p.arms.rows() + nf);
      Eigen::VectorXd fixed = x;
      for (int f : free) fixed[f] = 0;
      rhs.head(p.arms.rows()) = w.asDiagonal() * (p.torque - p.arms * fixed);
      rhs.tail(nf).setZero();
      a.setZero();
      for (int k = 0; k < nf; ++k) {
        a.col(k).head(p.arms.rows()) = w.asDiagonal() * p.arms.col(free[k]);
        const double price = p.price.size() > 0 ? p.price[free[k]] : 1.0;
        a(p.arms.rows() + k, k) = std::sqrt(eps) * price / p.cap[free[k]];
      }
      const Eigen::VectorXd sol = a.colPivHouseholderQr().solve(rhs);
      bool inside = true;
      for (int k = 0; k < nf; ++k) {
        x[free[k]] = sol[k];
        inside &= sol[k] >= p.floor[free[k]] - 1e-12 && sol[k] <= p.cap[free[k]] + 1e-12;
      }
      if (!inside) continue;
    }
    const double cost = AllocationCost(p, x, eps);
    if (cost < best_cost) best_cost = cost, best = x;
  }
  return best;
}

// The active-set solution against the exhaustive one: the same cost and tensions, inside the box
// (so exactly the tension of a held bundle, whose floor is its capacity).
void ExpectMatchesExhaustive(const AllocationProblem& p, int trial) {
  const Eigen::VectorXd got = AllocateTensions(p);
  const Eigen::VectorXd want = Exhaustive(p, 1e-8);
  ASSERT_EQ(got.size(), p.cap.size());
  EXPECT_NEAR(AllocationCost(p, got), AllocationCost(p, want), 1e-12) << "trial " << trial;
  for (int b = 0; b < got.size(); ++b) {
    EXPECT_NEAR(got[b], want[b], 1e-6 * p.cap[b]) << "trial " << trial << " bundle " << b;
    EXPECT_GE(got[b], p.floor[b]);
    EXPECT_LE(got[b], p.cap[b]);
  }
}

TEST(TorqueAllocation, MatchesTheExhaustiveSolverOnRandomLimbs) {
  std::mt19937_64 gen(20261126);
  std::uniform_real_distribution<double> u(-1, 1), pos(0.1, 1);
  for (int trial = 0; trial < 300; ++trial) {
    const int nj = 1 + trial % 2, nb = 1 + trial % 6;
    AllocationProblem p;
    p.arms = Eigen::MatrixXd(nj, nb);
    for (int j = 0; j < nj; ++j) {
      for (int b = 0; b < nb; ++b) p.arms(j, b) = (trial % 7 == 0 && b == 0) ? 0 : 0.02 * u(gen);
    }
    p.cap = Eigen::VectorXd(nb);
    p.floor = Eigen::VectorXd(nb);
    for (int b = 0; b < nb; ++b) {
      p.cap[b] = 50 * pos(gen);
      p.floor[b] = 0.05 * p.cap[b] * (trial % 3);
    }
    p.torque = Eigen::VectorXd(nj);
    for (int j = 0; j < nj; ++j) p.torque[j] = 0.8 * u(gen);
    ExpectMatchesExhaustive(p, trial);
  }
}

// Bundles whose floor is their capacity (held at a given tension): the exhaustive solver needs
// nothing special for them (floor and capacity are the same choice).
TEST(TorqueAllocation, HeldBundlesMatchTheExhaustiveSolverOnRandomLimbs) {
  std::mt19937_64 gen(20261127);
  std::uniform_real_distribution<double> u(-1, 1), pos(0.1, 1);
  for (int trial = 0; trial < 300; ++trial) {
    const int nj = 1 + trial % 2, nb = 2 + trial % 5;
    AllocationProblem p;
    p.arms = Eigen::MatrixXd(nj, nb);
    for (int j = 0; j < nj; ++j) {
      for (int b = 0; b < nb; ++b) p.arms(j, b) = 0.02 * u(gen);
    }
    p.cap = Eigen::VectorXd(nb);
    p.floor = Eigen::VectorXd(nb);
    p.price = Eigen::VectorXd(nb);
    for (int b = 0; b < nb; ++b) {
      p.cap[b] = 50 * pos(gen);
      p.floor[b] = 0.05 * p.cap[b];
      p.price[b] = b % 2 ? 10 : 1;
      if (b % 3 == trial % 3) p.floor[b] = p.cap[b] = 20 * pos(gen);  // held
    }
    p.torque = Eigen::VectorXd(nj);
    for (int j = 0; j < nj; ++j) p.torque[j] = 0.8 * u(gen);
    ExpectMatchesExhaustive(p, trial);
  }
}

// The case that stalled the two-joint arm's shoulder: a held biarticular flexor that both joints'
// demands would raise (its gradient points into the box the most). Solved by hand: it gives
// 0.015 x 9.26 N m on each joint, the extensors stay at their floors (the share term only lowers
// them), the one-joint flexors make up the rest.
TEST(TorqueAllocation, AHeldBundleLeavesTheRestOfTheDemandToTheOthers) {
  AllocationProblem p;
  p.arms = Eigen::MatrixXd(2, 5);  // bundles SF, SE, BF, EF, EE; joints shoulder, elbow
  p.arms << 0.02, -0.02, 0.015, 0, 0, 0, 0, 0.015, 0.015, -0.015;
  p.torque = Eigen::Vector2d(0.5, 0.2);
  p.cap = Eigen::VectorXd(5);
  p.cap << 42.73, 51.59, 9.26, 23.16, 21.10;
  p.floor = 0.05 * p.cap;
  p.floor[2] = p.cap[2];  // BF held at 9.26 N
  p.price = Eigen::VectorXd(5);
  p.price << 1, 1, 10, 1, 0.125;
  const Eigen::VectorXd t = AllocateTensions(p);
  EXPECT_EQ(t[2], 9.26);
  EXPECT_EQ(t[1], p.floor[1]);
  EXPECT_EQ(t[4], p.floor[4]);
  EXPECT_NEAR(t[0], (0.5 - 0.015 * 9.26 + 0.02 * p.floor[1]) / 0.02, 1e-5);
  EXPECT_NEAR(t[3], (0.2 - 0.015 * 9.26 + 0.015 * p.floor[4]) / 0.015, 1e-5);
}

TEST(TorqueAllocation, AnAntagonistPairMeetsAReachableDemandWithTheExtensorAtItsFloor) {
  // Flexor +8 mm, extensor -8 mm; 0.05 N m needs 6.25 N net.
  AllocationProblem p;
  p.arms = Eigen::RowVector2d(0.008, -0.008);
  p.torque = Eigen::VectorXd::Constant(1, 0.05);
  p.cap = Eigen::Vector2d(40, 20);
  p.floor = 0.05 * p.cap;
  const Eigen::VectorXd t = AllocateTensions(p);
  EXPECT_NEAR(p.arms.row(0).dot(t), 0.05, 1e-7 * 0.05);
  EXPECT_DOUBLE_EQ(t[1], p.floor[1]);
  // Two flexors share the demand by arm and capacity squared: T_b proportional to a_b cap_b^2.
  p.arms = Eigen::RowVector2d(0.008, 0.004);
  p.floor.setZero();
  const Eigen::VectorXd s = AllocateTensions(p);
  EXPECT_NEAR(p.arms.row(0).dot(s), 0.05, 1e-6);
  EXPECT_NEAR(s[0] / s[1], (0.008 * 40 * 40) / (0.004 * 20 * 20), 1e-3);
}

TEST(TorqueAllocation, AnUnreachableDemandSaturatesAtCapacity) {
  AllocationProblem p;
  p.arms = Eigen::RowVector2d(0.008, -0.008);
  p.torque = Eigen::VectorXd::Constant(1, 1.0);  // 125 N net: more than the flexor has
  p.cap = Eigen::Vector2d(40, 20);
  p.floor = Eigen::Vector2d(0, 0);
  const Eigen::VectorXd t = AllocateTensions(p);
  EXPECT_DOUBLE_EQ(t[0], 40);
  EXPECT_DOUBLE_EQ(t[1], 0);
}

}  // namespace file_torque_allocation_test
}  // namespace recruit::control
