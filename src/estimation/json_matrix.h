// The filter model file's JSON: its parser (field paths in its messages) and Eigen matrices and
// vectors written as arrays of rows. They are read by the common checkers (common/json_fields.h).
#pragma once

#include <Eigen/Dense>
#include <nlohmann/json.hpp>
#include <string>

#include "common/json_fields.h"
#include "common/result.h"

namespace recruit::estimation::json_io {

// json_fields::MatrixValue / VectorValue (the broadcast transition's reader calls them by these
// names).
inline Result<Eigen::MatrixXd> ReadMatrix(const nlohmann::json& j, const std::string& field,
                                          int rows, int cols) {
  return json_fields::MatrixValue(j, field, rows, cols);
}
inline Result<Eigen::VectorXd> ReadVector(const nlohmann::json& j, const std::string& field,
                                          int size) {
  return json_fields::VectorValue(j, field, size);
}

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

}  // namespace recruit::estimation::json_io
