#include "identification/nonnegative_qp.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <limits>

namespace recruit::identification {
namespace {

// The unconstrained minimiser over the passive set P (zero elsewhere).
Eigen::VectorXd SolvePassive(const Eigen::MatrixXd& Q, const Eigen::VectorXd& c,
                             const std::vector<bool>& passive) {
  std::vector<int> idx;
  for (int i = 0; i < static_cast<int>(passive.size()); ++i) {
    if (passive[i]) idx.push_back(i);
  }
  Eigen::VectorXd s = Eigen::VectorXd::Zero(c.size());
  if (idx.empty()) return s;
  const int p = static_cast<int>(idx.size());
  Eigen::MatrixXd Qp(p, p);
  Eigen::VectorXd cp(p);
  for (int a = 0; a < p; ++a) {
    cp[a] = c[idx[a]];
    for (int b = 0; b < p; ++b) Qp(a, b) = Q(idx[a], idx[b]);
  }
  const Eigen::VectorXd sp = Qp.ldlt().solve(cp);
  for (int a = 0; a < p; ++a) s[idx[a]] = sp[a];
  return s;
}

}  // namespace

Eigen::VectorXd NonNegativeQp(const Eigen::MatrixXd& Q, const Eigen::VectorXd& c,
                              const std::vector<bool>& free_in) {
  const int n = static_cast<int>(c.size());
  std::vector<bool> free = free_in.empty() ? std::vector<bool>(n, false) : free_in;
  std::vector<bool> passive = free;
  Eigen::VectorXd z = SolvePassive(Q, c, passive);
  // Gradient entries below this are rounding: the scale of Q z and c.
  const double tol = 1e3 * std::numeric_limits<double>::epsilon() *
                     std::max({c.cwiseAbs().maxCoeff(), Q.cwiseAbs().maxCoeff(), 1e-300}) *
                     std::max(1.0, static_cast<double>(n));
  for (int outer = 0; outer < 3 * n + 3; ++outer) {
    const Eigen::VectorXd w = c - Q * z;  // minus the gradient
    int enter = -1;
    double best = tol * std::max(1.0, z.cwiseAbs().maxCoeff());
    for (int i = 0; i < n; ++i) {
      if (!passive[i] && w[i] > best) {
        best = w[i];
        enter = i;
      }
    }
    if (enter < 0) break;  // KKT: every bound variable's gradient points into the bound
    passive[enter] = true;
    for (int inner = 0; inner <= n; ++inner) {
      const Eigen::VectorXd s = SolvePassive(Q, c, passive);
      // Step towards s until the first constrained passive variable reaches zero.
      double alpha = 1;
      int leave = -1;
      for (int i = 0; i < n; ++i) {
        if (passive[i] && !free[i] && s[i] <= 0) {
          const double t = z[i] / (z[i] - s[i]);
          if (t < alpha) {
            alpha = t;
            leave = i;
          }
        }
      }
      if (leave < 0) {
        z = s;
        break;
      }
      z += alpha * (s - z);
      z[leave] = 0;
      for (int i = 0; i < n; ++i) {
        if (passive[i] && !free[i] && z[i] <= 0) {
          passive[i] = false;
          z[i] = 0;
        }
      }
    }
  }
  return z;
}

}  // namespace recruit::identification
