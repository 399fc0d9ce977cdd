// Eigen matrices and vectors written into a filter model file's JSON as arrays of rows. Files are
// parsed by the common loader (common/json_file.h) and read by the common field checkers
// (common/json_fields.h).
#pragma once

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

namespace recruit::estimation::json_io {

nlohmann::json WriteMatrix(const Eigen::MatrixXd& M);
nlohmann::json WriteVector(const Eigen::VectorXd& v);

}  // namespace recruit::estimation::json_io
