#include "common/json_fields.h"

#include <cmath>

#include "common/short_text.h"

namespace recruit::json_fields {

using nlohmann::json;

namespace {

std::string Join(const std::set<std::string>& s) {
  std::string out;
  for (const auto& x : s) out += (out.empty() ? "" : ", ") + x;
  return out;
}

}  // namespace

Status CheckKeys(const json& j, const std::set<std::string>& allowed, const std::string& where) {
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (!allowed.count(it.key())) {
      return Error{where + ": unknown field '" + ShortText(it.key()) +
                   "'; allowed: " + Join(allowed)};
    }
  }
  return Status::Ok();
}

Status Number(const json& j, const std::string& key, const std::string& where, double* out,
              bool required, double lo, double hi, bool lo_open, const std::string& allowed) {
  if (!j.contains(key)) {
    if (required) return Error{where + ": missing field '" + key + "' (" + allowed + ")"};
    return Status::Ok();
  }
  const json& v = j.at(key);
  if (!v.is_number()) {
    return Error{where + "." + key + ": must be a number (" + allowed + "), got " +
                 ShortText(v.dump())};
  }
  const double x = v.get<double>();
  if (!std::isfinite(x) || x < lo || (lo_open && x == lo) || x > hi) {
    return Error{where + "." + key + ": " + ShortText(v.dump()) +
                 " is out of range; allowed: " + allowed};
  }
  *out = x;
  return Status::Ok();
}

Status Integer(const json& j, const std::string& key, const std::string& where, std::int64_t* out,
               bool required, std::int64_t lo, std::int64_t hi, const std::string& allowed) {
  if (!j.contains(key)) {
    if (required) return Error{where + ": missing field '" + key + "' (" + allowed + ")"};
    return Status::Ok();
  }
  const json& v = j.at(key);
  const bool whole = v.is_number_integer() &&
                     (v.is_number_unsigned() ? v.get<std::uint64_t>() <= std::uint64_t(hi) : true);
  if (!whole || v.get<std::int64_t>() < lo || v.get<std::int64_t>() > hi) {
    return Error{where + "." + key + ": " + ShortText(v.dump()) + "; allowed: " + allowed};
  }
  *out = v.get<std::int64_t>();
  return Status::Ok();
}

Status Unsigned(const json& j, const std::string& key, const std::string& where, std::uint64_t* out,
                bool required) {
  if (!j.contains(key)) {
    if (required) return Error{where + ": missing field '" + key + "' (a whole number >= 0)"};
    return Status::Ok();
  }
  const json& v = j.at(key);
  if (!v.is_number_unsigned()) {
    return Error{where + "." + key + ": " + ShortText(v.dump()) + "; allowed: a whole number >= 0"};
  }
  *out = v.get<std::uint64_t>();
  return Status::Ok();
}

Status String(const json& j, const std::string& key, const std::string& where, std::string* out,
              bool required) {
  if (!j.contains(key)) {
    if (required) return Error{where + ": missing field '" + key + "' (a string)"};
    return Status::Ok();
  }
  if (!j.at(key).is_string() || j.at(key).get<std::string>().empty()) {
    return Error{where + "." + key + ": must be a non-empty string, got " +
                 ShortText(j.at(key).dump())};
  }
  *out = j.at(key).get<std::string>();
  return Status::Ok();
}

Status Boolean(const json& j, const std::string& key, const std::string& where, bool* out) {
  if (!j.contains(key)) return Status::Ok();
  if (!j.at(key).is_boolean()) return Error{where + "." + key + ": must be true or false"};
  *out = j.at(key).get<bool>();
  return Status::Ok();
}

Status Vec3(const json& j, const std::string& key, const std::string& where, Eigen::Vector3d* out) {
  if (!j.contains(key)) return Status::Ok();
  const json& v = j.at(key);
  if (!v.is_array() || v.size() != 3) {
    return Error{where + "." + key + ": must be an array of 3 numbers [x, y, z], got " +
                 ShortText(v.dump())};
  }
  for (int i = 0; i < 3; ++i) {
    if (!v[i].is_number() || !std::isfinite(v[i].get<double>())) {
      return Error{where + "." + key + ": must be an array of 3 finite numbers, got " +
                   ShortText(v.dump())};
    }
    (*out)[i] = v[i].get<double>();
  }
  return Status::Ok();
}

}  // namespace recruit::json_fields
