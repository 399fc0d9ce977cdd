// Checked reads of JSON fields, one set for every input file read from JSON (tasks, sweep files,
// filter models): each names the field as `where.key`, quotes a bad value shortened and says
// what is allowed. A missing optional field leaves *out unchanged.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

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

// A whole number >= 0 that fits 64 bits (seeds).
Status Unsigned(const nlohmann::json& j, const std::string& key, const std::string& where,
                std::uint64_t* out, bool required);

// A non-empty string.
Status String(const nlohmann::json& j, const std::string& key, const std::string& where,
              std::string* out, bool required);

// true or false.
Status Boolean(const nlohmann::json& j, const std::string& key, const std::string& where,
               bool* out);

// [x, y, z] of finite numbers (optional).
Status Vec3(const nlohmann::json& j, const std::string& key, const std::string& where,
            Eigen::Vector3d* out);

}  // namespace recruit::json_fields
