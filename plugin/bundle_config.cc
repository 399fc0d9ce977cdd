#include "plugin/bundle_config.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <sstream>

#include "common/short_text.h"
#include "plugin/design_limits.h"

namespace recruit::sma {
namespace {

struct Key {
  const char* name;
  double lo, hi;  // allowed closed range
  bool lo_open;   // true: value must be > lo
  const char* unit;
  std::function<void(BundleConfig&, double)> set;
};

#define UNIT_FIELD(f) [](BundleConfig& c, double v) { c.unit.f = v; }

const std::vector<Key>& NumericKeys() {
  static const std::vector<Key> keys = {
      {"units", 1, 1e6, false, "", [](BundleConfig& c, double v) { c.units = int(v); }},
      {"wire_diameter", 0, 0.01, true, "m", UNIT_FIELD(wire_diameter)},
      {"wire_length", 0, 10, true, "m", UNIT_FIELD(wire_length)},
      {"coil_diameter", 0, 0.1, true, "m", UNIT_FIELD(coil_diameter)},
      {"turns", 1, 1e5, false, "", UNIT_FIELD(turns)},  // a coil has at least one turn
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
      {"eps_L", 0, AlloyDomain::kMaxStrain, true, "", UNIT_FIELD(eps_L)},  // NiTi: <= 8 %
      {"ref_length", 0, 1e3, true, "m", [](BundleConfig& c, double v) { c.ref_length = v; }},
      {"merge_temperature", 0, 10, false, "C",
       [](BundleConfig& c, double v) { c.merge_temperature = v; }},
      {"merge_xi", 0, 0.1, false, "", [](BundleConfig& c, double v) { c.merge_xi = v; }},
      {"update_period", 0, 1, false, "s", [](BundleConfig& c, double v) { c.update_period = v; }},
#define FAILURE_FIELD(f)          \
  [](BundleConfig& c, double v) { \
    c.failure.f = v;              \
    c.failure.given = true;       \
  }
      {"open_rate", 0, 3600, false, "per hour heated", FAILURE_FIELD(open_rate)},
      {"stuck_rate", 0, 3600, false, "per hour heated", FAILURE_FIELD(stuck_rate)},
      {"open_per_cycle", 0, 1, false, "per cycle", FAILURE_FIELD(open_per_cycle)},
      {"stuck_per_cycle", 0, 1, false, "per cycle", FAILURE_FIELD(stuck_per_cycle)},
      // A unit keeps at least 10 % of its force: beyond that it is a failure, not fatigue.
      {"fatigue_loss", 0, 0.9, false, "", FAILURE_FIELD(fatigue_loss)},
      {"fatigue_cycles", 0, 1e9, true, "cycles", FAILURE_FIELD(fatigue_cycles)},
      {"fatigue_stress", 0, 2e9, true, "Pa", FAILURE_FIELD(fatigue_stress)},
      {"fatigue_exponent", 0, 10, false, "", FAILURE_FIELD(fatigue_exponent)},
#undef FAILURE_FIELD
#define CENSUS_FIELD(f)           \
  [](BundleConfig& c, double v) { \
    c.census.f = v;               \
    c.census.given = true;        \
  }
      {"census_on", 0, 0.1, true, "s", CENSUS_FIELD(on)},
      {"census_off", 0, 0.1, true, "s", CENSUS_FIELD(off)},
      {"census_noise", 0, 10, false, "A", CENSUS_FIELD(noise)},
#undef CENSUS_FIELD
      {"bins", 2, 1e6, false, "cohorts (unit_model=binned)",
       [](BundleConfig& c, double v) { c.bins = int(v); }},
  };
  return keys;
}

#undef UNIT_FIELD

// "current=100 wire_diameter=1e-9" for the keys among `keys` that the configuration gave, as
// written; the keys' names with "(defaults)" when it gave none of them.
std::string Given(const std::map<std::string, std::string>& given,
                  std::initializer_list<const char*> keys) {
  std::string s, names;
  for (const char* k : keys) {
    names += (names.empty() ? "" : ", ") + std::string(k);
    const auto it = given.find(k);
    if (it != given.end()) s += (s.empty() ? "" : " ") + it->first + "=" + ShortText(it->second);
  }
  return s.empty() ? names + " (defaults)" : s;
}

std::string Num(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

// The alloy's domain (design_limits.h, AlloyDomain; plugin/README.md "Limits"): geometry that
// can exist, an ambient at which the cold wire is martensite, and a steady state below the
// temperature, stress and strain NiTi survives. Messages name the keys given (and values).
Status CheckDomain(const BundleConfig& c, const std::map<std::string, std::string>& given,
                   const std::string& where) {
  const UnitParams& p = c.unit;
  const bool spring = p.law == ForceLaw::kSpring;
  if ((spring || given.count("coil_diameter")) && !(p.coil_diameter > p.wire_diameter)) {
    return Error{where + Given(given, {"coil_diameter", "wire_diameter"}) +
                 ": the mean coil diameter " + GText(p.coil_diameter) +
                 " m must exceed the wire diameter " + GText(p.wire_diameter) +
                 " m (a coil's bore is D - d)"};
  }
  const double length = spring ? 3.14159265358979323846 * p.coil_diameter * p.turns : p.wire_length;
  const double min_length = AlloyDomain::kMinLengthPerDiameter * p.wire_diameter;
  if (length < min_length) {
    return Error{where +
                 (spring ? Given(given, {"turns", "coil_diameter", "wire_diameter"})
                         : Given(given, {"wire_length", "wire_diameter"})) +
                 ": the wire is " + GText(length) + " m long, shorter than " +
                 GText(AlloyDomain::kMinLengthPerDiameter) + " wire diameters (" +
                 GText(min_length) +
                 " m): its terminals would cool most of it, outside the lumped thermal model"};
  }
  if (!(p.ambient < p.As)) {
    return Error{where + Given(given, {"ambient", "As"}) + ": ambient " + GText(p.ambient) +
                 " C must be below As " + GText(p.As) +
                 " C: an unheated wire would contract by itself"};
  }
  const SteadyState s = Evaluate(p, false);
  if (!(s.on_temperature <= AlloyDomain::kMaxTemperature)) {
    return Error{where +
                 Given(given, {"current", "wire_diameter", "resistivity_A", "resistivity_M", "h",
                               "emissivity", "ambient"}) +
                 ": the wire settles at " + Num("%.3g", s.on_temperature) + " C when on, above " +
                 Num("%.0f", AlloyDomain::kMaxTemperature) +
                 " C where NiTi anneals and loses its trained memory; current <= " +
                 Num("%.3g", CurrentForTemperature(p, AlloyDomain::kMaxTemperature)) +
                 " A keeps it below"};
  }
  if (!(s.peak_stress() <= AlloyDomain::kMaxStress)) {
    return Error{where +
                 Given(given, {"prestretch", "prestrain", "series", "series_spring", "wire_length",
                               "wire_diameter", "coil_diameter", "turns", "E_A", "E_M", "G_A",
                               "G_M", "current", "C_A", "As", "Af"}) +
                 ": the wire stress reaches " + Num("%.4g", s.peak_stress() / 1e6) + " MPa " +
                 (s.on_stress >= s.off_stress ? "held on" : "off") +
                 " at the reference extension, above NiTi's martensite yield strength " +
                 Num("%.0f", AlloyDomain::kMaxStress / 1e6) + " MPa (deforms plastically)"};
  }
  if (!(s.off_strain <= AlloyDomain::kMaxStrain)) {
    return Error{where +
                 Given(given, {"prestretch", "prestrain", "series", "series_spring", "wire_length",
                               "E_M", "G_M", "eps_L"}) +
                 ": the off wire is strained " + Num("%.3g", 100 * s.off_strain) +
                 " % at the reference extension, beyond NiTi's recoverable " +
                 Num("%.0f", 100 * AlloyDomain::kMaxStrain) + " %"};
  }
  if (p.current > 0 && !(s.on_xi < 0.99)) {
    return Error{where +
                 Given(given, {"current", "ambient", "wire_diameter", "h", "emissivity",
                               "resistivity_M", "As", "Af", "prestretch", "prestrain", "series",
                               "series_spring", "E_A", "G_A", "C_A"}) +
                 ": a unit held on settles at " + Num("%.3g", s.on_temperature) +
                 " C and never contracts (its effective temperature stays below As " + GText(p.As) +
                 " C); current >= " + Num("%.3g", CurrentForTemperature(p, p.Af)) +
                 " A reaches Af unloaded (current=0: units that never heat)"};
  }
  return Status::Ok();
}

// Failure settings that cannot happen together: exclusive outcomes of one cycle whose
// probabilities add past 1, more scheduled failures than units.
Status CheckFailures(const BundleConfig& c, const std::map<std::string, std::string>& given,
                     const std::string& where) {
  const FailureConfig& f = c.failure;
  if (f.open_per_cycle + f.stuck_per_cycle > 1) {
    return Error{where + Given(given, {"open_per_cycle", "stuck_per_cycle"}) +
                 ": a cycle's failure probabilities add to " +
                 GText(f.open_per_cycle + f.stuck_per_cycle) +
                 ", more than 1 (one cycle fails a unit open or stuck, not both)"};
  }
  long scheduled = 0;
  for (const auto& e : f.schedule) scheduled += e.count;
  if (scheduled > c.units) {
    return Error{where + Given(given, {"failures", "units"}) + ": the schedule fails " +
                 std::to_string(scheduled) + " units of a bundle of " + std::to_string(c.units) +
                 " (at most units)"};
  }
  return Status::Ok();
}

}  // namespace

std::vector<std::string> BundleConfig::Keys() {
  std::vector<std::string> k = {"law"};
  for (const Key& key : NumericKeys()) {
    const std::string name = key.name;
    if (name != "bins" && name.rfind("census_", 0) != 0) k.push_back(name);
  }
  k.push_back("failures");
  k.push_back("unit_model");  // the unit model's keys last (the older keys keep their places)
  k.push_back("bins");
  for (const char* c : {"census_on", "census_off", "census_noise"}) k.push_back(c);
  return k;
}

Result<std::vector<FailureConfig::Event>> FailureConfig::ParseSchedule(const std::string& text) {
  std::vector<Event> events;
  std::stringstream in(text);
  std::string item;
  const std::string allowed =
      ": must be time:count:mode[,...] with time in [0, 1e9] s, count a whole number >= 1 and "
      "mode open or stuck, e.g. 30:6:open,60:2:stuck";
  while (std::getline(in, item, ',')) {
    const auto a = item.find(':'), b = item.rfind(':');
    if (a == std::string::npos || a == b) return Error{"'" + ShortText(item) + "'" + allowed};
    const std::string t = item.substr(0, a), n = item.substr(a + 1, b - a - 1),
                      mode = item.substr(b + 1);
    char* end = nullptr;
    errno = 0;
    const double time = std::strtod(t.c_str(), &end);
    const bool time_ok = end != t.c_str() && *end == '\0' && errno == 0 && time >= 0 && time <= 1e9;
    end = nullptr;
    const double count = std::strtod(n.c_str(), &end);
    const bool count_ok = end != n.c_str() && *end == '\0' && count >= 1 && count <= 1e6 &&
                          count == std::floor(count);
    if (!time_ok || !count_ok || (mode != "open" && mode != "stuck")) {
      return Error{"'" + ShortText(item) + "'" + allowed};
    }
    events.push_back({time, static_cast<int>(count), mode == "stuck"});
  }
  if (events.empty()) return Error{"no event" + allowed};
  std::stable_sort(events.begin(), events.end(),
                   [](const Event& x, const Event& y) { return x.time < y.time; });
  return events;
}

Result<BundleConfig> BundleConfig::FromText(const std::string& actuator, const std::string& text) {
  const std::string where = "actuator '" + actuator + "': ";
  std::istringstream in(text);
  std::string token;
  std::vector<std::pair<std::string, std::string>> pairs;
  while (in >> token) {
    const auto eq = token.find('=');
    if (eq != std::string::npos && eq > 0 && eq + 1 == token.size()) {
      return Error{where + ShortText(token) + " has no value: give one, or leave the key out"};
    }
    if (eq == std::string::npos || eq == 0) {
      return Error{where + "'" + ShortText(token) + "' is not key=value"};
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
  std::map<std::string, std::string> given;  // key -> value as written
  double prestrain = std::nan("");
  for (const auto& [key, value] : pairs) {
    if (value.empty()) continue;  // an unset MJCF config key: keep the default
    if (!given.emplace(key, value).second) {
      return Error{where + "key '" + ShortText(key) + "' given twice"};
    }
    if (key == "law") {
      if (value == "wire") {
        c.unit.law = ForceLaw::kWire;
      } else if (value == "spring") {
        c.unit.law = ForceLaw::kSpring;
      } else {
        return Error{where + "law=" + ShortText(value) +
                     " is invalid: allowed values are wire, spring"};
      }
      continue;
    }
    if (key == "unit_model") {
      if (value == "exact") {
        c.unit_model = UnitModelKind::kExact;
      } else if (value == "binned") {
        c.unit_model = UnitModelKind::kBinned;
      } else {
        return Error{where + "unit_model=" + ShortText(value) +
                     " is invalid: allowed values are exact, binned"};
      }
      continue;
    }
    if (key == "failures") {
      auto events = FailureConfig::ParseSchedule(value);
      if (!events.ok()) {
        return events.failure().In(where + "failures=" + ShortText(value) + " is invalid: ");
      }
      c.failure.schedule = std::move(events).value();
      c.failure.given = true;
      continue;
    }
    const Key* spec = nullptr;
    for (const Key& k : NumericKeys()) {
      if (key == k.name) spec = &k;
    }
    if (spec == nullptr) {
      std::string allowed;
      for (const std::string& k : Keys()) allowed += (allowed.empty() ? "" : ", ") + k;
      return Error{where + "unknown key '" + ShortText(key) + "' (allowed: " + allowed + ")"};
    }
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    if (end == value.c_str() || *end != '\0' || errno == ERANGE || !std::isfinite(v)) {
      return Error{where + key + "=" + ShortText(value) + " is not a finite number"};
    }
    const bool low_bad = spec->lo_open ? !(v > spec->lo) : !(v >= spec->lo);
    if (low_bad || v > spec->hi) {
      return Error{where + key + "=" + ShortText(value) + " is out of range: must be in " +
                   (spec->lo_open ? "(" : "[") + GText(spec->lo) + ", " + GText(spec->hi) + "]" +
                   (spec->unit[0] ? std::string(" ") + spec->unit : std::string())};
    }
    if ((key == "units" || key == "series" || key == "parallel" || key == "bins") &&
        v != std::floor(v)) {
      return Error{where + key + "=" + ShortText(value) + " must be a whole number"};
    }
    if (key == "prestrain") {
      prestrain = v;
    } else {
      spec->set(c, v);
    }
  }
  if (!std::isnan(prestrain)) {
    if (given.count("prestretch")) {
      return Error{where + "give prestrain or prestretch, not both"};
    }
    if (c.unit.law != ForceLaw::kWire) {
      return Error{where + "prestrain is for law=wire; use prestretch (m) with law=spring"};
    }
    c.unit.prestretch = prestrain * c.unit.wire_length * c.unit.series;  // whole unit
  }
  if (given.count("bins") && c.unit_model != UnitModelKind::kBinned) {
    return Error{where + "bins=" + ShortText(given["bins"]) +
                 " is for unit_model=binned (unit_model=exact keeps every cohort the merge "
                 "tolerances allow): give unit_model=binned, or leave bins out"};
  }
  RECRUIT_TRY(CheckFailures(c, given, where));
  auto check = UnitModel::Create(c.unit);
  if (!check.ok()) return check.failure().In(where);
  RECRUIT_TRY(CheckDomain(c, given, where));
  return c;
}

}  // namespace recruit::sma
