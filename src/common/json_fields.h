// Checked reads of JSON fields, one set for every input file read from JSON (tasks, sweep files,
// filter models): each names the field as `where.key`, quotes a bad value shortened and says
// what is allowed. A missing optional field leaves *out unchanged. Every failure is bad input.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "common/result.h"

namespace recruit::json_fields {

// Every key of the object `j` is in `allowed` (else "where: unknown field 'k'; allowed: ...").
Status CheckKeys(const nlohmann::json& j, const std::set<std::string>& allowed,
                 const std::string& where);

// A finite number with lo <= x (lo_open: lo < x) and x <= hi; `allowed` says so in words.
Status Number(const nlohmann::json& j, const std::string& key, const std::string& where,
              double* out, bool required, double lo, double hi, bool lo_open,
              const std::string& allowed);

// A whole number lo <= n <= hi (a JSON integer, not 2.0).
Status Integer(const nlohmann::json& j, const std::string& key, const std::string& where,
               std::int64_t* out, bool required, std::int64_t lo, std::int64_t hi,
               const std::string& allowed);

// An array of `size` whole numbers lo <= n <= hi (size < 0: any length).
Status Integers(const nlohmann::json& j, const std::string& key, const std::string& where,
                std::vector<std::int64_t>* out, bool required, int size, std::int64_t lo,
                std::int64_t hi, const std::string& allowed);

// A whole number >= 0 that fits 64 bits (seeds).
Status Unsigned(const nlohmann::json& j, const std::string& key, const std::string& where,
                std::uint64_t* out, bool required);

// One of the strings `allowed` ("where.key: \"x\"; allowed: \"a\", \"b\"").
Status OneOf(const nlohmann::json& j, const std::string& key, const std::string& where,
             std::string* out, bool required, const std::vector<std::string>& allowed);

// A non-empty array of non-empty strings (names).
Status Strings(const nlohmann::json& j, const std::string& key, const std::string& where,
               std::vector<std::string>* out, bool required);

// An object; `allowed` says what it holds, for the messages. Nothing is read.
Status Object(const nlohmann::json& j, const std::string& key, const std::string& where,
              bool required, const std::string& allowed);

// A rows x cols matrix: an array of `rows` arrays of `cols` finite numbers (row-major);
// rows / cols < 0: any.
Status Matrix(const nlohmann::json& j, const std::string& key, const std::string& where,
              Eigen::MatrixXd* out, bool required, int rows, int cols);

// An array of `size` finite numbers (size < 0: any).
Status Vector(const nlohmann::json& j, const std::string& key, const std::string& where,
              Eigen::VectorXd* out, bool required, int size);

// Matrix and Vector of a value already found; `field` names it ("model.json.H").
Result<Eigen::MatrixXd> MatrixValue(const nlohmann::json& v, const std::string& field, int rows,
                                    int cols);
Result<Eigen::VectorXd> VectorValue(const nlohmann::json& v, const std::string& field, int size);

// A non-empty string.
Status String(const nlohmann::json& j, const std::string& key, const std::string& where,
              std::string* out, bool required);

// true or false.
Status Boolean(const nlohmann::json& j, const std::string& key, const std::string& where,
               bool* out);

// An array of `size` booleans (size < 0: any length); `allowed` says what they mean.
Status Booleans(const nlohmann::json& j, const std::string& key, const std::string& where,
                std::vector<bool>* out, bool required, int size, const std::string& allowed);

// [x, y, z] of finite numbers (optional).
Status Vec3(const nlohmann::json& j, const std::string& key, const std::string& where,
            Eigen::Vector3d* out);

}  // namespace recruit::json_fields
