#include "estimation/json_matrix.h"

#include <cmath>

namespace recruit::json_io {

Result<Eigen::MatrixXd> ReadMatrix(const nlohmann::json& j, const std::string& field, int rows,
                                   int cols) {
  const std::string shape = (rows >= 0 ? std::to_string(rows) : std::string("r")) + " x " +
                            (cols >= 0 ? std::to_string(cols) : std::string("c"));
  if (!j.is_array()) {
    return Error{field + ": must be an array of rows (" + shape + " numbers, row-major)"};
  }
  const int r = static_cast<int>(j.size());
  if (rows >= 0 && r != rows) {
    return Error{field + ": must have " + std::to_string(rows) + " rows (" + shape + "), got " +
                 std::to_string(r)};
  }
  int c = cols;
  if (r > 0 && c < 0) c = j[0].is_array() ? static_cast<int>(j[0].size()) : -1;
  if (c < 0) c = 0;
  Eigen::MatrixXd M(r, c);
  for (int i = 0; i < r; ++i) {
    const auto& row = j[i];
    if (!row.is_array() || static_cast<int>(row.size()) != c) {
      return Error{field + ": row " + std::to_string(i) + " must be an array of " +
                   std::to_string(c) + " numbers (" + shape + ")"};
    }
    for (int k = 0; k < c; ++k) {
      if (!row[k].is_number()) {
        return Error{field + ": entry (" + std::to_string(i) + ", " + std::to_string(k) +
                     ") is not a number"};
      }
      const double v = row[k].get<double>();
      if (!std::isfinite(v)) {
        return Error{field + ": entry (" + std::to_string(i) + ", " + std::to_string(k) +
                     ") is not finite"};
      }
      M(i, k) = v;
    }
  }
  return M;
}

Result<Eigen::VectorXd> ReadVector(const nlohmann::json& j, const std::string& field, int size) {
  if (!j.is_array()) return Error{field + ": must be an array of numbers"};
  const int n = static_cast<int>(j.size());
  if (size >= 0 && n != size) {
    return Error{field + ": must have " + std::to_string(size) + " entries, got " +
                 std::to_string(n)};
  }
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) {
    if (!j[i].is_number())
      return Error{field + ": entry " + std::to_string(i) + " is not a number"};
    v(i) = j[i].get<double>();
    if (!std::isfinite(v(i)))
      return Error{field + ": entry " + std::to_string(i) + " is not finite"};
  }
  return v;
}

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

}  // namespace recruit::json_io
