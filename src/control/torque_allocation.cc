#include "control/torque_allocation.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace recruit::control {
namespace {

// 1 / s_j^2 per joint (0 for a joint no bundle moves).
Eigen::VectorXd JointWeights(const AllocationProblem& p) {
  Eigen::VectorXd w(p.arms.rows());
  for (int j = 0; j < p.arms.rows(); ++j) {
    const double span = p.arms.row(j).cwiseAbs().dot(p.cap);
    w[j] = span > 0 ? 1.0 / (span * span) : 0.0;
  }
  return w;
}

double Price(const AllocationProblem& p, int b) { return p.price.size() > 0 ? p.price[b] : 1.0; }

enum Bound : char { kFree, kLower, kUpper };

// The minimum over the free variables with the others held: Q_FF x_F = c_F - Q_FB x_B.
Eigen::VectorXd FreeMinimum(const Eigen::MatrixXd& Q, const Eigen::VectorXd& c,
                            const std::vector<Bound>& state, const Eigen::VectorXd& x) {
  std::vector<int> free;
  for (int i = 0; i < static_cast<int>(state.size()); ++i) {
    if (state[i] == kFree) free.push_back(i);
  }
  Eigen::VectorXd out = x;
  if (free.empty()) return out;
  const int nf = static_cast<int>(free.size());
  Eigen::MatrixXd qff(nf, nf);
  Eigen::VectorXd rhs(nf);
  for (int a = 0; a < nf; ++a) {
    rhs[a] = c[free[a]];
    for (int i = 0; i < x.size(); ++i) {
      if (state[i] != kFree) rhs[a] -= Q(free[a], i) * x[i];
    }
    for (int b = 0; b < nf; ++b) qff(a, b) = Q(free[a], free[b]);
  }
  const Eigen::VectorXd sol = qff.llt().solve(rhs);
  for (int a = 0; a < nf; ++a) out[free[a]] = sol[a];
  return out;
}

}  // namespace

double AllocationCost(const AllocationProblem& p, const Eigen::VectorXd& tensions, double eps) {
  const Eigen::VectorXd w = JointWeights(p);
  const Eigen::VectorXd r = p.arms * tensions - p.torque;
  double share = 0;
  for (int b = 0; b < tensions.size(); ++b) {
    const double x = Price(p, b) * tensions[b] / p.cap[b];
    share += x * x;
  }
  return r.cwiseProduct(r).dot(w) + eps * share;
}

Eigen::VectorXd AllocateTensions(const AllocationProblem& p, double eps) {
  const int nb = static_cast<int>(p.cap.size());
  const Eigen::VectorXd w = JointWeights(p);
  // The cost is (1/2) x'Qx - c'x + const with Q = 2 (A'WA + eps D^-2), c = 2 A'W torque.
  Eigen::MatrixXd Q = p.arms.transpose() * w.asDiagonal() * p.arms;
  for (int b = 0; b < nb; ++b) {
    const double price = Price(p, b);
    Q(b, b) += eps * price * price / (p.cap[b] * p.cap[b]);
  }
  const Eigen::VectorXd c = p.arms.transpose() * w.asDiagonal() * p.torque;
  // Start at the floor, every variable held there.
  Eigen::VectorXd x = p.floor;
  std::vector<Bound> state(nb, kLower);
  for (int iter = 0; iter < 50 * (nb + 1); ++iter) {
    const Eigen::VectorXd target = FreeMinimum(Q, c, state, x);
    // The longest step towards it that stays inside the box; a variable that stops it is held.
    double alpha = 1;
    int blocking = -1;
    for (int i = 0; i < nb; ++i) {
      if (state[i] != kFree || target[i] == x[i]) continue;
      const double limit = target[i] < x[i] ? p.floor[i] : p.cap[i];
      const double a = (limit - x[i]) / (target[i] - x[i]);
      if (a < alpha) alpha = a, blocking = i;
    }
    x += alpha * (target - x);
    if (blocking >= 0) {
      x[blocking] = target[blocking] < x[blocking] ? p.floor[blocking] : p.cap[blocking];
      state[blocking] = x[blocking] == p.floor[blocking] ? kLower : kUpper;
      continue;
    }
    // At the free minimum: release the held variable whose gradient points most into the box.
    const Eigen::VectorXd grad = Q * x - c;
    int release = -1;
    double best = 0;
    for (int i = 0; i < nb; ++i) {
      // A bundle held at floor == cap is never released: freed, its first step would be blocked
      // at once and it would be held again, at its floor, the same release chosen on every pass
      // and the others never freed (they stayed at their floors until the iterations ran out).
      if (!(p.floor[i] < p.cap[i])) continue;
      const double into = state[i] == kLower ? -grad[i] : state[i] == kUpper ? grad[i] : 0;
      if (into > best * (1 + 1e-12) && into > 1e-14 * std::abs(c[i]) + 1e-300) {
        best = into, release = i;
      }
    }
    if (release < 0) break;  // the KKT conditions hold
    state[release] = kFree;
  }
  return x.cwiseMax(p.floor).cwiseMin(p.cap);
}

Eigen::VectorXd RoundToUnits(const AllocationProblem& p, const Eigen::VectorXd& tensions,
                             const Eigen::VectorXd& unit_force, const Eigen::VectorXi& units,
                             double eps) {
  const int nb = static_cast<int>(tensions.size());
  const int reach = nb <= 4 ? 1 : 0;  // candidates beyond floor and ceiling
  std::vector<std::vector<double>> choices(nb);
  for (int b = 0; b < nb; ++b) {
    if (!(unit_force[b] > 0)) {
      choices[b] = {tensions[b]};  // no unit pulls here: leave it
      continue;
    }
    const double n = tensions[b] / unit_force[b];
    const int lo = std::max(0, static_cast<int>(std::floor(n)) - reach);
    const int hi = std::min(units[b], static_cast<int>(std::ceil(n)) + reach);
    for (int k = lo; k <= hi; ++k) choices[b].push_back(k * unit_force[b]);
    if (choices[b].empty()) choices[b] = {tensions[b]};
  }
  // Every combination (at most 4^4 or 2^nb), in a fixed order; ties keep the first.
  Eigen::VectorXd x(nb), best = tensions;
  double best_cost = std::numeric_limits<double>::infinity();
  std::vector<size_t> pick(nb, 0);
  while (true) {
    for (int b = 0; b < nb; ++b) x[b] = choices[b][pick[b]];
    const double cost = AllocationCost(p, x, eps);
    if (cost < best_cost) best_cost = cost, best = x;
    int b = 0;
    while (b < nb && ++pick[b] == choices[b].size()) pick[b++] = 0;
    if (b == nb) break;
  }
  return best;
}

}  // namespace recruit::control
