#include "attach/sizing.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace recruit::attach {
namespace {

std::string Num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// The unit for diameter d with the geometry chosen, its current and coupling spring set so that
// a held-on wire settles at limits.steady_temperature and pulls design_stress x area when the
// segment is stretched by its whole stroke (the tendon's longest, off units just taut).
Result<sma::UnitModel> DesignUnit(double d, double length, int series, const SizingLimits& limits) {
  sma::UnitParams p;
  p.wire_diameter = d;
  p.wire_length = length;
  p.series = series;
  p.parallel = 1;
  const double area = 0.25 * M_PI * d * d;
  const double k_hot = limits.design_stress * area / (p.eps_L * length);  // wire + spring
  const double k_wire = p.E_A * area / length;
  p.series_spring = 1.0 / (1.0 / k_hot - 1.0 / k_wire);
  p.prestretch = series * p.eps_L * length;
  // Current: bisection on the steady on-temperature (monotone in the current).
  double lo = 1e-4, hi = 20;
  for (int i = 0; i < 60; ++i) {
    p.current = 0.5 * (lo + hi);
    auto u = sma::UnitModel::Create(p);
    if (!u.ok()) return Error{u.error(), u.code()};
    (u->on_temperature() > limits.steady_temperature ? hi : lo) = p.current;
  }
  // Never above Dynalloy's 1 s contraction current; a wire that then settles too cool to
  // transform fully under the design stress is refused (SizeBundle takes a thicker one).
  p.current = std::min(lo, sma::UnitLimits::ForWire(d).max_current);
  auto unit = sma::UnitModel::Create(p);
  if (unit.ok() && unit->on_temperature() < p.Af + limits.design_stress / p.C_A + 10) {
    return Error{"too cool at the datasheet current"};
  }
  return unit;
}

// One wire of diameter d per segment: the unit, and how many such wires make the peak force.
struct Wire {
  sma::UnitParams unit;  // parallel 1, prestretch at ref_length
  int wires = 0;
  double time_constant = 0;  // s
};

Result<Wire> WireFor(double d, double length, int series, double gear, const SizingInput& in,
                     const SizingLimits& limits) {
  auto unit = DesignUnit(d, length, series, limits);
  if (!unit.ok()) return unit.failure();
  const double l_mid = 0.5 * (in.length_min + in.length_max);
  const double s_mid = unit->params().prestretch - gear * (in.length_max - l_mid);
  const double per_wire = gear * unit->Tension(0.0, s_mid);
  Wire w;
  w.unit = unit->params();
  w.unit.prestretch = series * w.unit.eps_L * length - gear * (in.length_max - in.ref_length);
  w.wires = static_cast<int>(std::ceil(in.peak_force / per_wire - 1e-9));
  w.time_constant = unit->time_constant();
  return w;
}

// More units for the same force, so that one unit is at most 1/units_per_holding_force of the
// force that holds the limb's own weight: first fewer wires per unit, then, at one wire each,
// thinner stock wire (more wires of it, the same force; they also cool faster), up to
// max_units_resolution units.
void RefineForResolution(const SizingInput& in, const SizingLimits& limits, BundleDesign& out) {
  const bool weight = in.holding_force > 0;
  const double holding = weight ? in.holding_force : limits.rest_tension_fraction * in.peak_force;
  if (!(holding > 0) || limits.units_per_holding_force <= 0) return;
  const double wanted = std::ceil(limits.units_per_holding_force * in.peak_force / holding);
  const int target = static_cast<int>(std::min<double>(wanted, limits.max_units_resolution));
  const int wires = out.units * out.unit.parallel;
  // At least `target` units by fewer wires per unit (the same wires; this may pass
  // max_units_resolution, which bounds the thinner wire taken below).
  const int parallel = std::max(1, wires / target);
  if (out.units < target && parallel < out.unit.parallel) {
    out.unit.parallel = parallel;
    out.units = (wires + parallel - 1) / parallel;
  }
  const std::vector<double>& stock = StockDiameters();
  for (auto d = stock.rbegin(); d != stock.rend() && out.units < target; ++d) {
    if (*d >= out.unit.wire_diameter) continue;
    auto wire = WireFor(*d, out.unit.wire_length, out.unit.series, out.gear, in, limits);
    if (!wire.ok()) continue;
    if (wire->wires > limits.max_units_resolution) break;
    out.unit = wire->unit;
    out.units = wire->wires;
  }
  if (out.units < wanted) {
    // The rule stops at its cap, or the next thinner wire would pass it.
    const std::string why =
        out.units >= limits.max_units_resolution
            ? "the rule stops at " + std::to_string(limits.max_units_resolution) + " units"
            : "no thinner stock wire makes the force within " +
                  std::to_string(limits.max_units_resolution) + " units of one wire";
    out.notes.push_back(
        "resolution: " + std::to_string(out.units) + " units, fewer than the " + Num(wanted) +
        " that would make one unit 1/" + std::to_string(limits.units_per_holding_force) +
        (weight ? " of the limb's holding force (" + Num(holding) + " N; "
                : " of the co-contraction that holds a limb with no weight on it (" + Num(holding) +
                      " N; ") +
        why + ")");
  }
}

}  // namespace

const std::vector<double>& StockDiameters() {
  static const std::vector<double> d = {0.025e-3, 0.038e-3, 0.05e-3, 0.076e-3, 0.1e-3,  0.127e-3,
                                        0.15e-3,  0.2e-3,   0.25e-3, 0.3e-3,   0.38e-3, 0.51e-3};
  return d;
}

std::vector<std::pair<std::string, std::string>> BundleDesign::ConfigPairs() const {
  return {{"units", std::to_string(units)},
          {"wire_diameter", Num(unit.wire_diameter)},
          {"wire_length", Num(unit.wire_length)},
          {"series", std::to_string(unit.series)},
          {"parallel", std::to_string(unit.parallel)},
          {"current", Num(unit.current)},
          {"series_spring", Num(unit.series_spring)},
          {"prestretch", Num(unit.prestretch)}};
}

Result<BundleDesign> SizeBundle(const SizingInput& in, const SizingLimits& limits) {
  const std::string where = "sizing bundle '" + in.name + "': ";
  if (!(std::isfinite(in.peak_force) && in.peak_force > 0)) {
    return Error{where + "peak force " + Num(in.peak_force) + " N is invalid: must be > 0"};
  }
  if (!(std::isfinite(in.excursion) && in.excursion >= 0 && std::isfinite(in.length_min) &&
        std::isfinite(in.length_max) && std::isfinite(in.ref_length))) {
    return Error{where + "tendon excursion " + Num(in.excursion) + " m is invalid"};
  }
  if (!(limits.stroke_use >= 0.2 && limits.stroke_use <= 0.95)) {
    return Error{where + "stroke use " + Num(limits.stroke_use) +
                 " is invalid: must be in 0.2..0.95"};
  }
  BundleDesign out;
  const double eps_L = sma::UnitParams{}.eps_L;
  // Wire per unit for the stroke, then a transmission when it exceeds the credible length.
  const double max_unit = limits.max_series * limits.max_segment_length;
  double needed = in.excursion / (limits.stroke_use * eps_L);
  if (needed > max_unit) {
    out.gear = std::floor(100 * max_unit / needed) / 100;
    if (out.gear <= 0) out.gear = 0.01;
    char buf[160];
    std::snprintf(buf, sizeof buf,
                  "lever/pulley ratio %.2f (actuator gear %.2f): the units move %.2f x the tendon "
                  "and pull it with %.2f x their tension",
                  out.gear, out.gear, out.gear, out.gear);
    out.transmission = buf;
    out.notes.push_back("stroke: " + Num(1000 * in.excursion) + " mm of tendon would need " +
                        Num(needed) + " m of wire per unit (> " + Num(max_unit) +
                        " m): transmission " + Num(out.gear));
  }
  needed *= out.gear;
  int series = 1;
  double length = 0.1;
  if (in.excursion > 0) {
    series = std::max(1, static_cast<int>(std::ceil(needed / limits.max_segment_length - 1e-9)));
    length = std::max(limits.min_segment_length, std::ceil(needed / series / 0.005 - 1e-9) * 0.005);
  } else {
    out.notes.push_back("the tendon does not move over the joint ranges: default 0.1 m wire");
  }
  // Diameter: the thinnest stock wire whose bundle needs at most 2 wires per segment within
  // max_units units (fast cooling, and enough units for the controller's resolution), unless
  // that wire cools slower than max_time_constant: then the thickest wire that does not, with up
  // to max_parallel wires per segment and max_units_fast units (more wires, the bandwidth kept),
  // else up to max_units_resolution units; a slow wire only when no fast one makes the force.
  const std::vector<double>& stock = StockDiameters();
  bool chosen = false, fast_found = false, many_found = false;
  sma::UnitParams fast;  // the thickest fast-enough design so far
  int fast_units = 0;
  // The same within max_units_resolution units, for a force no design of max_units_fast units
  // makes fast enough (a slow bundle is the last resort).
  sma::UnitParams many;
  int many_units = 0;
  for (std::size_t i = 0; i < stock.size(); ++i) {
    auto wire = WireFor(stock[i], length, series, out.gear, in, limits);
    if (!wire.ok()) {
      if (i + 1 < stock.size() || fast_found) continue;
      return Error{where + wire.error(), wire.code()};
    }
    const int wires = wire->wires;
    const int parallel = (wires + limits.max_units - 1) / limits.max_units;
    sma::UnitParams p = wire->unit;
    p.parallel = parallel;
    const int units = (wires + parallel - 1) / parallel;
    const bool fast_enough = wire->time_constant <= limits.max_time_constant;
    if (parallel <= 2 && (fast_enough || !(fast_found || many_found))) {
      out.unit = p, out.units = units, chosen = true;
      break;
    }
    const int parallel_fast = (wires + limits.max_units_fast - 1) / limits.max_units_fast;
    if (parallel_fast <= limits.max_parallel && fast_enough) {
      fast = p;
      fast.parallel = parallel_fast;
      fast_units = (wires + parallel_fast - 1) / parallel_fast;
      fast_found = true;
    }
    const int parallel_many =
        (wires + limits.max_units_resolution - 1) / limits.max_units_resolution;
    if (parallel_many <= limits.max_parallel && fast_enough) {
      many = p;
      many.parallel = parallel_many;
      many_units = (wires + parallel_many - 1) / parallel_many;
      many_found = true;
    }
    if (parallel <= 2 || i + 1 == stock.size()) {
      if (fast_found) {
        out.unit = fast, out.units = fast_units;
      } else if (many_found) {
        out.unit = many, out.units = many_units;
      } else {
        out.unit = p, out.units = units;
      }
      chosen = true;
      break;
    }
  }
  if (!chosen) return Error{where + "no stock wire meets the force"};
  RefineForResolution(in, limits, out);
  auto u = sma::UnitModel::Create(out.unit);
  if (!u.ok()) return Error{where + u.error(), u.code()};
  const sma::UnitLimits datasheet = sma::UnitLimits::ForWire(out.unit.wire_diameter);
  auto stretch = [&](double l) { return out.Stretch(l, in.ref_length); };
  const double n = out.units;
  const double l_mid = 0.5 * (in.length_min + in.length_max);
  out.force_mid = out.gear * n * u->Tension(0.0, stretch(l_mid));
  out.force_short = out.gear * n * u->Tension(0.0, stretch(in.length_min));
  const double long_tension = u->Tension(0.0, stretch(in.length_max));
  out.force_long = out.gear * n * long_tension;
  out.peak_stress = u->WireStress(long_tension);
  out.steady_temperature = u->on_temperature();
  out.max_current = datasheet.max_current;
  if (out.unit.current > datasheet.max_current) {
    out.notes.push_back("current " + Num(out.unit.current) + " A above the datasheet's " +
                        Num(datasheet.max_current) + " A");
  }
  out.stroke = u->recoverable_stretch();
  const double wires = n * out.unit.parallel * out.unit.series;
  out.wire_total = wires * out.unit.wire_length;
  out.mass = out.unit.density * 0.25 * M_PI * std::pow(out.unit.wire_diameter, 2) * out.wire_total;
  out.power = wires * u->HeatingPower(true, 0.0);
  out.time_constant = u->time_constant();
  out.cooling_time = datasheet.cooling_time;
  if (out.time_constant > limits.max_time_constant) {
    out.notes.push_back("thermal time constant " + Num(out.time_constant) + " s, above " +
                        Num(limits.max_time_constant) +
                        " s (--max-time-constant): no stock wire that cools fast enough makes " +
                        Num(in.peak_force) + " N within " + std::to_string(limits.max_parallel) +
                        " wires per unit and " + std::to_string(limits.max_units_resolution) +
                        " units; the loop will be slow (a lower --force, or a larger gear)");
  }
  return out;
}

}  // namespace recruit::attach
