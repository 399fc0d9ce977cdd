// Reading Eigen matrices and vectors from JSON with messages naming the file and field.
#pragma once

#include <Eigen/Dense>
#include <nlohmann/json.hpp>
#include <string>

#include "common/result.h"

namespace recruit::json_io {

// A JSON array of `rows` arrays of `cols` finite numbers (row-major). rows/cols < 0: any.
Result<Eigen::MatrixXd> ReadMatrix(const nlohmann::json& j, const std::string& field, int rows,
                                   int cols);
// A JSON array of `size` finite numbers (size < 0: any).
Result<Eigen::VectorXd> ReadVector(const nlohmann::json& j, const std::string& field, int size);

nlohmann::json WriteMatrix(const Eigen::MatrixXd& M);
nlohmann::json WriteVector(const Eigen::VectorXd& v);

}  // namespace recruit::json_io
