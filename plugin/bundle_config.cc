#include "plugin/bundle_config.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <set>
#include <sstream>

#include "common/short_text.h"

namespace recruit::sma {
namespace {

struct Key {
  const char* name;
  double lo, hi;  // allowed closed range
  bool lo_open;   // true: value must be > lo
  const char* unit;
  std::function<void(BundleConfig&, double)> set;
};

// A value as quoted in a message: at most 40 characters.
std::string Short(const std::string& v) { return v.size() <= 40 ? v : v.substr(0, 37) + "..."; }

#define UNIT_FIELD(f) [](BundleConfig& c, double v) { c.unit.f = v; }

const std::vector<Key>& NumericKeys() {
  static const std::vector<Key> keys = {
      {"units", 1, 1e6, false, "", [](BundleConfig& c, double v) { c.units = int(v); }},
      {"wire_diameter", 0, 0.01, true, "m", UNIT_FIELD(wire_diameter)},
      {"wire_length", 0, 10, true, "m", UNIT_FIELD(wire_length)},
      {"coil_diameter", 0, 0.1, true, "m", UNIT_FIELD(coil_diameter)},
      {"turns", 0, 1e5, true, "", UNIT_FIELD(turns)},
      {"series", 1, 1000, false, "", [](BundleConfig& c, double v) { c.unit.series = int(v); }},
      {"parallel", 1, 1000, false, "", [](BundleConfig& c, double v) { c.unit.parallel = int(v); }},
      {"series_spring", 0, 1e9, false, "N/m (0 = rigid)", UNIT_FIELD(series_spring)},
      // wire law: prestretch = prestrain * wire_length * series (every segment strained alike)
      {"prestrain", -1, 1, false, "", nullptr},
      {"prestretch", -10, 10, false, "m", UNIT_FIELD(prestretch)},
      {"current", 0, 100, false, "A", UNIT_FIELD(current)},
      {"ambient", -100, 200, false, "C", UNIT_FIELD(ambient)},
      {"h", 0, 1e6, false, "W/(m^2 K) (0 = natural convection)", UNIT_FIELD(h)},
      {"emissivity", 0, 1, false, "", UNIT_FIELD(emissivity)},
      {"density", 0, 1e5, true, "kg/m^3", UNIT_FIELD(density)},
      {"specific_heat", 0, 1e5, true, "J/(kg K)", UNIT_FIELD(specific_heat)},
      {"latent_heat", 0, 1e6, false, "J/kg", UNIT_FIELD(latent_heat)},
      {"resistivity_M", 0, 1, true, "ohm m", UNIT_FIELD(resistivity_M)},
      {"resistivity_A", 0, 1, true, "ohm m", UNIT_FIELD(resistivity_A)},
      {"As", -100, 300, false, "C", UNIT_FIELD(As)},
      {"Af", -100, 300, false, "C", UNIT_FIELD(Af)},
      {"Ms", -100, 300, false, "C", UNIT_FIELD(Ms)},
      {"Mf", -100, 300, false, "C", UNIT_FIELD(Mf)},
      {"C_A", 0, 1e9, true, "Pa/K", UNIT_FIELD(C_A)},
      {"C_M", 0, 1e9, true, "Pa/K", UNIT_FIELD(C_M)},
      {"E_A", 0, 1e12, true, "Pa", UNIT_FIELD(E_A)},
      {"E_M", 0, 1e12, true, "Pa", UNIT_FIELD(E_M)},
      {"G_A", 0, 1e12, true, "Pa", UNIT_FIELD(G_A)},
      {"G_M", 0, 1e12, true, "Pa", UNIT_FIELD(G_M)},
      {"eps_L", 0, 0.2, true, "", UNIT_FIELD(eps_L)},
      {"ref_length", 0, 1e3, true, "m", [](BundleConfig& c, double v) { c.ref_length = v; }},
      {"merge_temperature", 0, 10, false, "C",
       [](BundleConfig& c, double v) { c.merge_temperature = v; }},
      {"merge_xi", 0, 0.1, false, "", [](BundleConfig& c, double v) { c.merge_xi = v; }},
      {"update_period", 0, 1, false, "s", [](BundleConfig& c, double v) { c.update_period = v; }},
  };
  return keys;
}

#undef UNIT_FIELD

}  // namespace

std::vector<std::string> BundleConfig::Keys() {
  std::vector<std::string> k = {"law"};
  for (const Key& key : NumericKeys()) k.push_back(key.name);
  return k;
}

Result<BundleConfig> BundleConfig::FromText(const std::string& actuator, const std::string& text) {
  const std::string where = "actuator '" + actuator + "': ";
  std::istringstream in(text);
  std::string token;
  std::vector<std::pair<std::string, std::string>> pairs;
  while (in >> token) {
    const auto eq = token.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == token.size()) {
      return Error{where + "'" + Short(token) + "' is not key=value"};
    }
    pairs.emplace_back(token.substr(0, eq), token.substr(eq + 1));
  }
  return FromPairs(actuator, where, pairs);
}

Result<BundleConfig> BundleConfig::FromPairs(
    const std::string& actuator, const std::string& where,
    const std::vector<std::pair<std::string, std::string>>& pairs) {
  BundleConfig c;
  c.actuator = actuator;
  std::set<std::string> seen;
  double prestrain = std::nan("");
  for (const auto& [key, value] : pairs) {
    if (value.empty()) continue;  // an unset MJCF config key: keep the default
    if (!seen.insert(key).second) return Error{where + "key '" + key + "' given twice"};
    if (key == "law") {
      if (value == "wire") {
        c.unit.law = ForceLaw::kWire;
      } else if (value == "spring") {
        c.unit.law = ForceLaw::kSpring;
      } else {
        return Error{where + "law=" + Short(value) +
                     " is invalid: allowed values are wire, spring"};
      }
      continue;
    }
    const Key* spec = nullptr;
    for (const Key& k : NumericKeys()) {
      if (key == k.name) spec = &k;
    }
    if (spec == nullptr) {
      std::string allowed;
      for (const std::string& k : Keys()) allowed += (allowed.empty() ? "" : ", ") + k;
      return Error{where + "unknown key '" + Short(key) + "' (allowed: " + allowed + ")"};
    }
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    if (end == value.c_str() || *end != '\0' || errno == ERANGE || !std::isfinite(v)) {
      return Error{where + key + "=" + Short(value) + " is not a finite number"};
    }
    const bool low_bad = spec->lo_open ? !(v > spec->lo) : !(v >= spec->lo);
    if (low_bad || v > spec->hi) {
      return Error{where + key + "=" + Short(value) + " is out of range: must be in " +
                   (spec->lo_open ? "(" : "[") + GText(spec->lo) + ", " + GText(spec->hi) + "]" +
                   (spec->unit[0] ? std::string(" ") + spec->unit : std::string())};
    }
    if ((key == "units" || key == "series" || key == "parallel") && v != std::floor(v)) {
      return Error{where + key + "=" + Short(value) + " must be a whole number"};
    }
    if (key == "prestrain") {
      prestrain = v;
    } else {
      spec->set(c, v);
    }
  }
  if (!std::isnan(prestrain)) {
    if (seen.count("prestretch")) {
      return Error{where + "give prestrain or prestretch, not both"};
    }
    if (c.unit.law != ForceLaw::kWire) {
      return Error{where + "prestrain is for law=wire; use prestretch (m) with law=spring"};
    }
    c.unit.prestretch = prestrain * c.unit.wire_length * c.unit.series;  // whole unit
  }
  auto check = UnitModel::Create(c.unit);
  if (!check.ok()) return Error{where + check.error()};
  return c;
}

}  // namespace recruit::sma
