#include "estimation/json_matrix.h"

namespace recruit::estimation::json_io {

nlohmann::json WriteMatrix(const Eigen::MatrixXd& M) {
  nlohmann::json j = nlohmann::json::array();
  for (Eigen::Index i = 0; i < M.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index k = 0; k < M.cols(); ++k) row.push_back(M(i, k));
    j.push_back(row);
  }
  return j;
}

nlohmann::json WriteVector(const Eigen::VectorXd& v) {
  nlohmann::json j = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) j.push_back(v(i));
  return j;
}

}  // namespace recruit::estimation::json_io
