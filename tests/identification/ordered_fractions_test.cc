// OrderedFractions against an exhaustive search over the faces of the order (K = 2).
#include "identification/ordered_fractions.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <limits>
#include <random>

namespace recruit::identification {
namespace {

// min v^T M v / 2 + q^T v  s.t. A v <= b, by trying every subset of constraints as equalities
// (KKT system) and keeping the best feasible point: exact for a strictly convex problem.
Eigen::VectorXd ExhaustiveQp(const Eigen::MatrixXd& M, const Eigen::VectorXd& q,
                             const Eigen::MatrixXd& A, const Eigen::VectorXd& b) {
  const int n = static_cast<int>(q.size()), nc = static_cast<int>(b.size());
  double best = std::numeric_limits<double>::infinity();
  Eigen::VectorXd arg;
  for (int mask = 0; mask < (1 << nc); ++mask) {
    std::vector<int> act;
    for (int i = 0; i < nc; ++i) {
      if ((mask >> i) & 1) act.push_back(i);
    }
    const int a = static_cast<int>(act.size());
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n + a, n + a);
    Eigen::VectorXd rhs(n + a);
    K.topLeftCorner(n, n) = M;
    rhs.head(n) = -q;
    for (int r = 0; r < a; ++r) {
      K.block(n + r, 0, 1, n) = A.row(act[r]);
      K.block(0, n + r, n, 1) = A.row(act[r]).transpose();
      rhs[n + r] = b[act[r]];
    }
    Eigen::FullPivLU<Eigen::MatrixXd> lu(K);
    if (lu.rank() < n + a) continue;  // dependent constraints: another subset covers the face
    const Eigen::VectorXd v = lu.solve(rhs).head(n);
    if (((A * v - b).array() > 1e-10).any()) continue;
    const double f = 0.5 * v.dot(M * v) + q.dot(v);
    if (f < best) best = f, arg = v;
  }
  return arg;
}

TEST(OrderedFractions, MatchesExhaustiveSearchOverTheOrdersFaces) {
  const TransientChain c =
      TransientChain::Uniform(6, 1.0);  // cold, heat1, heat2, hot, cool1, cool2
  const int m = 6;
  // The four free states (heat1, heat2, cool1, cool2) and the order with cold = xc, hot = xh:
  // xc >= heat1 >= heat2 >= xh and xh <= cool1 <= cool2 <= xc, as A v <= b.
  const std::vector<int> vars = {c.heat(1), c.heat(2), c.cool(1), c.cool(2)};
  std::mt19937 rng(5);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(0, 1);
  int moved = 0;
  for (int trial = 0; trial < 100; ++trial) {
    Eigen::VectorXd xi(m);
    for (int i = 0; i < m; ++i) xi[i] = u(rng);
    xi[c.cold()] = 0.7 + 0.3 * u(rng);
    xi[c.hot()] = 0.3 * u(rng);
    const double xc = xi[c.cold()], xh = xi[c.hot()];
    Eigen::MatrixXd R(m + 2, m);
    for (int i = 0; i < R.size(); ++i) R.data()[i] = g(rng);
    Eigen::MatrixXd M = R.transpose() * R + 0.01 * Eigen::MatrixXd::Identity(m, m);
    Eigen::VectorXd grad(m);
    for (int i = 0; i < m; ++i) grad[i] = g(rng);
    const Eigen::VectorXd got = OrderedFractions(c, xi, M, grad);
    EXPECT_EQ(got[c.cold()], xc);
    EXPECT_EQ(got[c.hot()], xh);
    EXPECT_LE(FractionOrderViolation(c, got), 1e-9) << "trial " << trial;
    // The same problem in the four free states: step = v - xi, cold and hot fixed.
    Eigen::MatrixXd Mv(4, 4);
    Eigen::VectorXd qv(4);
    for (int a = 0; a < 4; ++a) {
      qv[a] = grad[vars[a]];
      for (int b2 = 0; b2 < 4; ++b2) Mv(a, b2) = M(vars[a], vars[b2]);
      for (int b2 = 0; b2 < 4; ++b2) qv[a] -= M(vars[a], vars[b2]) * xi[vars[b2]];
    }
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(6, 4);
    Eigen::VectorXd b = Eigen::VectorXd::Zero(6);
    A(0, 0) = 1, b[0] = xc;     // heat1 <= xc
    A(1, 1) = 1, A(1, 0) = -1;  // heat2 <= heat1
    A(2, 1) = -1, b[2] = -xh;   // heat2 >= xh
    A(3, 2) = -1, b[3] = -xh;   // cool1 >= xh
    A(4, 2) = 1, A(4, 3) = -1;  // cool1 <= cool2
    A(5, 3) = 1, b[5] = xc;     // cool2 <= xc
    const Eigen::VectorXd want = ExhaustiveQp(Mv, qv, A, b);
    ASSERT_EQ(want.size(), 4);
    for (int a = 0; a < 4; ++a) EXPECT_NEAR(got[vars[a]], want[a], 1e-6) << "trial " << trial;
    Eigen::VectorXd free_step = xi - M.ldlt().solve(grad);
    moved += FractionOrderViolation(c, free_step) > 0;
  }
  EXPECT_GT(moved, 50);  // most unconstrained steps leave the order: the constraint is exercised
}

TEST(OrderedFractions, ProjectionLeavesAnOrderedChainAsItIs) {
  const TransientChain c = TransientChain::Uniform(8, 1.0);  // K = 3
  Eigen::VectorXd xi(8);
  xi << 1.0, 0.9, 0.5, 0.2, 0.1, 0.3, 0.6, 0.95;  // cold, heat1..3, hot, cool1..3
  EXPECT_EQ(FractionOrderViolation(c, xi), 0.0);
  const Eigen::VectorXd p =
      OrderedFractions(c, xi, Eigen::MatrixXd::Identity(8, 8), Eigen::VectorXd::Zero(8));
  EXPECT_LT((p - xi).cwiseAbs().maxCoeff(), 1e-6);
  xi[3] = 0.6;  // heat3 above heat2: the projection averages the pair (pool adjacent violators)
  EXPECT_NEAR(FractionOrderViolation(c, xi), 0.1, 1e-15);
  const Eigen::VectorXd q =
      OrderedFractions(c, xi, Eigen::MatrixXd::Identity(8, 8), Eigen::VectorXd::Zero(8));
  EXPECT_NEAR(q[2], 0.55, 1e-6);
  EXPECT_NEAR(q[3], 0.55, 1e-6);
}

}  // namespace
}  // namespace recruit::identification
