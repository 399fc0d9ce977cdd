#include "identification/ordered_fractions.h"

#include <algorithm>

#include "identification/identification.h"
#include "identification/nonnegative_qp.h"

namespace recruit::identification {

Eigen::VectorXd OrderedFractions(const TransientChain& c, const Eigen::VectorXd& xi,
                                 const Eigen::MatrixXd& M, const Eigen::VectorXd& g) {
  const int K = c.chain_length, m = c.num_states();
  const double xc = xi[c.cold()], xh = xi[c.hot()];
  const double span = std::max(xc - xh, 0.0);
  Eigen::VectorXd a0 = Eigen::VectorXd::Constant(m, xc);
  a0[c.hot()] = xh;
  for (int i = 1; i <= K; ++i) a0[c.cool(i)] = xh;
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(m, 2 * K + 2);
  for (int j = 0; j <= K; ++j) {
    for (int i = j + 1; i <= K; ++i) {
      B(c.heat(i), j) = -1;
      B(c.cool(i), K + 1 + j) = 1;
    }
  }
  Eigen::MatrixXd Q = B.transpose() * M * B;
  Eigen::VectorXd lin = -B.transpose() * (M * (a0 - xi) + g);
  const double w = 1e6 * std::max(Q.trace() / Q.rows(), 1e-300);
  for (int path = 0; path < 2; ++path) {
    Eigen::VectorXd e = Eigen::VectorXd::Zero(B.cols());
    e.segment(path * (K + 1), K + 1).setOnes();
    Q += 2 * w * e * e.transpose();
    lin += 2 * w * span * e;
  }
  Eigen::VectorXd out = a0 + B * NonNegativeQp(Q, lin);
  // The penalty closes each path to rounding: keep every state between the ends.
  return out.cwiseMax(std::min(xc, xh)).cwiseMin(std::max(xc, xh));
}

double FractionOrderViolation(const TransientChain& c, const Eigen::VectorXd& xi) {
  TransientChain reversed = c;  // the fraction's order is the force's, reversed
  reversed.force = -xi;
  return OrderViolation(reversed);
}

}  // namespace recruit::identification
