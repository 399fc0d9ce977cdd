// NonNegativeQp against an exhaustive search over the active sets and a closed form.
#include "identification/nonnegative_qp.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <limits>
#include <random>

namespace recruit::identification {
namespace {

double Objective(const Eigen::MatrixXd& Q, const Eigen::VectorXd& c, const Eigen::VectorXd& z) {
  return 0.5 * z.dot(Q * z) - c.dot(z);
}

// The minimum over every choice of constrained variables held at zero whose unconstrained
// minimiser over the rest is feasible: the exact optimum of a strictly convex problem.
double ExhaustiveMinimum(const Eigen::MatrixXd& Q, const Eigen::VectorXd& c,
                         const std::vector<bool>& free) {
  const int n = static_cast<int>(c.size());
  double best = std::numeric_limits<double>::infinity();
  for (int mask = 0; mask < (1 << n); ++mask) {
    std::vector<int> idx;
    bool skip = false;
    for (int i = 0; i < n; ++i) {
      const bool zero = (mask >> i) & 1;
      if (zero && free[i]) skip = true;
      if (!zero) idx.push_back(i);
    }
    if (skip) continue;
    Eigen::VectorXd z = Eigen::VectorXd::Zero(n);
    if (!idx.empty()) {
      const int p = static_cast<int>(idx.size());
      Eigen::MatrixXd Qp(p, p);
      Eigen::VectorXd cp(p);
      for (int a = 0; a < p; ++a) {
        cp[a] = c[idx[a]];
        for (int b = 0; b < p; ++b) Qp(a, b) = Q(idx[a], idx[b]);
      }
      const Eigen::VectorXd zp = Qp.llt().solve(cp);
      for (int a = 0; a < p; ++a) z[idx[a]] = zp[a];
    }
    bool feasible = true;
    for (int i = 0; i < n; ++i) feasible &= free[i] || z[i] >= -1e-12;
    if (feasible) best = std::min(best, Objective(Q, c, z));
  }
  return best;
}

TEST(NonNegativeQp, MatchesExhaustiveSearchOnRandomProblems) {
  std::mt19937 rng(11);
  std::normal_distribution<double> g;
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 1 + trial % 7;
    const int rows = n + trial % 3;  // some nearly singular, all positive definite
    Eigen::MatrixXd A(rows, n);
    for (int i = 0; i < A.size(); ++i) A.data()[i] = g(rng);
    Eigen::MatrixXd Q = A.transpose() * A;
    Q.diagonal().array() += 1e-3;
    Eigen::VectorXd c(n);
    for (int i = 0; i < n; ++i) c[i] = g(rng);
    std::vector<bool> free(n, false);
    if (trial % 4 == 0) free[0] = true;
    const Eigen::VectorXd z = NonNegativeQp(Q, c, free);
    for (int i = 0; i < n; ++i) {
      if (!free[i]) EXPECT_GE(z[i], 0.0) << "trial " << trial;
    }
    const double want = ExhaustiveMinimum(Q, c, free);
    EXPECT_NEAR(Objective(Q, c, z), want, 1e-9 * (1 + std::abs(want))) << "trial " << trial;
  }
}

TEST(NonNegativeQp, DiagonalProblemIsClippedUnconstrainedSolution) {
  Eigen::MatrixXd Q = Eigen::Vector4d(2, 1, 4, 0.5).asDiagonal();
  const Eigen::Vector4d c(1, -3, 2, -1);
  const Eigen::VectorXd z = NonNegativeQp(Q, c, {false, false, false, true});
  EXPECT_NEAR(z[0], 0.5, 1e-14);
  EXPECT_EQ(z[1], 0.0);
  EXPECT_NEAR(z[2], 0.5, 1e-14);
  EXPECT_NEAR(z[3], -2.0, 1e-14);  // free: the unconstrained value
}

}  // namespace
}  // namespace recruit::identification
