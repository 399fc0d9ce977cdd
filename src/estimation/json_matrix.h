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

// The deepest nesting ParseJson accepts (filter model files nest 4 levels).
inline constexpr int kMaxJsonDepth = 64;

// Parses JSON `text` read from `path`. Errors are messages, never exceptions: malformed JSON
// (line, column), a number too large for a double (e.g. 1e999) and nesting deeper than
// kMaxJsonDepth (checked as the tree is built, level by level, so that a 70,000-deep document
// cannot exhaust the stack) each name the file and the field path (e.g.
// "transition.interior[1][0]"), with the offending text shortened (ShortText, common/short_text.h).
Result<nlohmann::json> ParseJson(const std::string& text, const std::string& path);

nlohmann::json WriteMatrix(const Eigen::MatrixXd& M);
nlohmann::json WriteVector(const Eigen::VectorXd& v);

}  // namespace recruit::json_io
