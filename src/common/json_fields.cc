#include "common/json_fields.h"

#include <algorithm>
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

// "2 x 3", "r x 3" (any number of rows), ...
std::string Shape(int rows, int cols) {
  return (rows >= 0 ? std::to_string(rows) : std::string("r")) + " x " +
         (cols >= 0 ? std::to_string(cols) : std::string("c"));
}

// A JSON integer lo <= n <= hi (not 2.0, not one beyond 64 bits).
bool WholeIn(const json& v, std::int64_t lo, std::int64_t hi) {
  if (!v.is_number_integer()) return false;
  if (v.is_number_unsigned() && v.get<std::uint64_t>() > std::uint64_t(hi)) return false;
  return v.get<std::int64_t>() >= lo && v.get<std::int64_t>() <= hi;
}

// An array field of `size` entries (size < 0: any) of type T, each one `entry_ok` accepts
// (else "where.key[i]: X; allowed: entry_allowed").
template <class T, class EntryOk>
Status ArrayField(const json& j, const std::string& key, const std::string& where,
                  std::vector<T>* out, bool required, int size, const std::string& allowed,
                  const std::string& entry_allowed, EntryOk entry_ok) {
  if (!j.contains(key)) {
    if (required) return Error{where + ": missing field '" + key + "' (" + allowed + ")"};
    return Status::Ok();
  }
  const json& v = j.at(key);
  const std::string field = where + "." + key;
  if (!v.is_array() || (size >= 0 && static_cast<int>(v.size()) != size)) {
    return Error{field + ": " + ShortText(v.dump()) + "; allowed: " + allowed};
  }
  std::vector<T> values;
  for (size_t i = 0; i < v.size(); ++i) {
    if (!entry_ok(v[i])) {
      return Error{field + "[" + std::to_string(i) + "]: " + ShortText(v[i].dump()) +
                   "; allowed: " + entry_allowed};
    }
    values.push_back(v[i].get<T>());
  }
  *out = std::move(values);
  return Status::Ok();
}

// A finite number, else "field: must be a finite number, got X".
Status FiniteNumber(const json& v, const std::string& field, double* out) {
  if (!v.is_number() || !std::isfinite(v.get<double>())) {
    return Error{field + ": must be a finite number, got " + ShortText(v.dump())};
  }
  *out = v.get<double>();
  return Status::Ok();
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
  if (!WholeIn(v, lo, hi)) {
    return Error{where + "." + key + ": " + ShortText(v.dump()) + "; allowed: " + allowed};
  }
  *out = v.get<std::int64_t>();
  return Status::Ok();
}

Status Integers(const json& j, const std::string& key, const std::string& where,
                std::vector<std::int64_t>* out, bool required, int size, std::int64_t lo,
                std::int64_t hi, const std::string& allowed) {
  return ArrayField(j, key, where, out, required, size, allowed, allowed,
                    [lo, hi](const json& x) { return WholeIn(x, lo, hi); });
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

Status OneOf(const json& j, const std::string& key, const std::string& where, std::string* out,
             bool required, const std::vector<std::string>& allowed) {
  std::string names;
  for (const auto& a : allowed) names += (names.empty() ? "" : ", ") + json(a).dump();
  if (!j.contains(key)) {
    if (required) return Error{where + ": missing field '" + key + "' (one of " + names + ")"};
    return Status::Ok();
  }
  const json& v = j.at(key);
  if (!v.is_string() ||
      std::find(allowed.begin(), allowed.end(), v.get<std::string>()) == allowed.end()) {
    return Error{where + "." + key + ": " + ShortText(v.dump()) + "; allowed: " + names};
  }
  *out = v.get<std::string>();
  return Status::Ok();
}

Status Strings(const json& j, const std::string& key, const std::string& where,
               std::vector<std::string>* out, bool required) {
  if (!j.contains(key)) {
    if (required) return Error{where + ": missing field '" + key + "' (an array of names)"};
    return Status::Ok();
  }
  const json& v = j.at(key);
  if (!v.is_array() || v.empty()) {
    return Error{where + "." + key + ": must be a non-empty array of names, got " +
                 ShortText(v.dump())};
  }
  std::vector<std::string> names;
  for (size_t i = 0; i < v.size(); ++i) {
    if (!v[i].is_string() || v[i].get<std::string>().empty()) {
      return Error{where + "." + key + "[" + std::to_string(i) +
                   "]: must be a non-empty string, got " + ShortText(v[i].dump())};
    }
    names.push_back(v[i].get<std::string>());
  }
  *out = std::move(names);
  return Status::Ok();
}

Status Object(const json& j, const std::string& key, const std::string& where, bool required,
              const std::string& allowed) {
  if (!j.contains(key)) {
    if (required) return Error{where + ": missing field '" + key + "' (" + allowed + ")"};
    return Status::Ok();
  }
  if (!j.at(key).is_object()) {
    return Error{where + "." + key + ": must be an object (" + allowed + "), got " +
                 ShortText(j.at(key).dump())};
  }
  return Status::Ok();
}

Result<Eigen::MatrixXd> MatrixValue(const json& v, const std::string& field, int rows, int cols) {
  const std::string shape = Shape(rows, cols);
  if (!v.is_array()) {
    return Error{field + ": must be an array of rows (a " + shape + " matrix, row-major), got " +
                 ShortText(v.dump())};
  }
  const int r = static_cast<int>(v.size());
  if (rows >= 0 && r != rows) {
    return Error{field + ": must have " + std::to_string(rows) + " rows (a " + shape +
                 " matrix), got " + std::to_string(r)};
  }
  int c = cols;
  if (r > 0 && c < 0) c = v[0].is_array() ? static_cast<int>(v[0].size()) : -1;
  if (c < 0) c = 0;
  Eigen::MatrixXd M(r, c);
  for (int i = 0; i < r; ++i) {
    const json& row = v[i];
    const std::string at = field + "[" + std::to_string(i) + "]";
    if (!row.is_array() || static_cast<int>(row.size()) != c) {
      return Error{at + ": must be an array of " + std::to_string(c) + " numbers (row " +
                   std::to_string(i) + " of a " + shape + " matrix), got " + ShortText(row.dump())};
    }
    for (int k = 0; k < c; ++k) {
      RECRUIT_TRY(FiniteNumber(row[k], at + "[" + std::to_string(k) + "]", &M(i, k)));
    }
  }
  return M;
}

Result<Eigen::VectorXd> VectorValue(const json& v, const std::string& field, int size) {
  if (!v.is_array()) {
    return Error{field + ": must be an array of " +
                 (size >= 0 ? std::to_string(size) + " " : std::string()) + "numbers, got " +
                 ShortText(v.dump())};
  }
  const int n = static_cast<int>(v.size());
  if (size >= 0 && n != size) {
    return Error{field + ": must have " + std::to_string(size) + " entries, got " +
                 std::to_string(n)};
  }
  Eigen::VectorXd x(n);
  for (int i = 0; i < n; ++i) {
    RECRUIT_TRY(FiniteNumber(v[i], field + "[" + std::to_string(i) + "]", &x(i)));
  }
  return x;
}

Status Matrix(const json& j, const std::string& key, const std::string& where, Eigen::MatrixXd* out,
              bool required, int rows, int cols) {
  if (!j.contains(key)) {
    if (required) {
      return Error{where + ": missing field '" + key + "' (a " + Shape(rows, cols) +
                   " matrix, an array of rows)"};
    }
    return Status::Ok();
  }
  auto M = MatrixValue(j.at(key), where + "." + key, rows, cols);
  if (!M.ok()) return M.failure();
  *out = std::move(M).value();
  return Status::Ok();
}

Status Vector(const json& j, const std::string& key, const std::string& where, Eigen::VectorXd* out,
              bool required, int size) {
  if (!j.contains(key)) {
    if (required) return Error{where + ": missing field '" + key + "' (an array of numbers)"};
    return Status::Ok();
  }
  auto v = VectorValue(j.at(key), where + "." + key, size);
  if (!v.ok()) return v.failure();
  *out = std::move(v).value();
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

Status Booleans(const json& j, const std::string& key, const std::string& where,
                std::vector<bool>* out, bool required, int size, const std::string& allowed) {
  return ArrayField(j, key, where, out, required, size, allowed, "true or false",
                    [](const json& x) { return x.is_boolean(); });
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
