// C literals and constant arrays of an exported package's real type (recruit_real).
#pragma once

#include <cstdio>
#include <string>
#include <vector>

namespace recruit::exporter {

enum class Precision { kDouble, kFloat };

// C literals of the package's type: exact round trip for double (%.17g), the nearest float
// (%.9g with an f suffix) for float.
class Writer {
 public:
  explicit Writer(Precision p) : p_(p) {}
  std::string Num(double v) const {
    char buf[64];
    if (p_ == Precision::kFloat) {
      std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(static_cast<float>(v)));
    } else {
      std::snprintf(buf, sizeof buf, "%.17g", v);
    }
    std::string s = buf;
    if (s.find_first_of(".e") == std::string::npos) s += ".0";
    return p_ == Precision::kFloat ? s + "f" : s;
  }
  // {a, b, ...} of reals.
  std::string List(const std::vector<double>& v) const {
    std::string s = "{";
    for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + Num(v[i]);
    return s + "}";
  }
  template <class T>
  std::string Array(const std::string& type, const std::string& name, const std::vector<T>& v,
                    bool real) const {
    std::string s = "static const " + type + " " + name + "[" + std::to_string(v.size()) + "] = {";
    for (size_t i = 0; i < v.size(); ++i) {
      s += (i % 6 == 0 ? "\n    " : " ") +
           (real ? Num(static_cast<double>(v[i])) : std::to_string(static_cast<long>(v[i])));
      if (i + 1 < v.size()) s += ",";
    }
    return s + "};\n";
  }
  bool is_float() const { return p_ == Precision::kFloat; }

 private:
  Precision p_;
};

}  // namespace recruit::exporter
