#include "estimation/transit_weights.h"

#include <algorithm>
#include <cmath>

namespace recruit::estimation {

Eigen::VectorXd TransitWeights(const Eigen::MatrixXd& interior, const Eigen::MatrixXd& H) {
  const int m = static_cast<int>(interior.cols());
  Eigen::VectorXd w = Eigen::VectorXd::Zero(m);
  if (interior.rows() != m || H.cols() != m) return w;
  for (int j = 0; j < m; ++j) {
    if (!(interior(j, j) < 1.0)) continue;
    int next = -1;
    for (int i = 0; i < m; ++i) {
      if (i != j && interior(i, j) > 0 && (next < 0 || interior(i, j) > interior(next, j))) {
        next = i;
      }
    }
    if (next < 0) continue;
    for (int r = 0; r < H.rows(); ++r) {
      const double range = H.row(r).maxCoeff() - H.row(r).minCoeff();
      if (range > 0) w[j] = std::max(w[j], std::abs(H(r, next) - H(r, j)) / range);
    }
  }
  return w;
}

}  // namespace recruit::estimation
