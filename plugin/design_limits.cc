#include "plugin/design_limits.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace recruit::sma {
namespace {

// A unit held on at `stretch` until settled: the fixed point of the exact thermal step and the
// implicit phase solve does not depend on the step, so 400 steps of tau / 10 (40 tau) reach it
// (as SmaBundle::SettledOnTension).
UnitState SettleOn(const UnitModel& m, double stretch) {
  UnitState s = RestState(m, stretch);
  const double decay = m.DecayFactor(m.time_constant() / 10);
  for (int i = 0; i < 400; ++i) AdvanceUnitWithDecay(m, s, true, stretch, decay);
  return s;
}

// Time from state s, switched off, until xi >= 0.995: steps of tau / 100, at most 100 tau.
double CoolingTime(const UnitModel& m, UnitState s, double stretch) {
  const double dt = m.time_constant() / 100;
  const double decay = m.DecayFactor(dt);
  for (int i = 0; i < 10000; ++i) {
    if (s.xi >= 0.995) return i * dt;
    AdvanceUnitWithDecay(m, s, false, stretch, decay);
  }
  return std::numeric_limits<double>::infinity();
}

// The model cools the default unit to 99.5 % relaxed in 2.2 times Dynalloy's cooling time (it
// cools to the literature Mf = 42 C and releases the latent heat on the way): a cooling time
// counts as past the datasheet's beyond 2.5 times it.
constexpr double kCoolingFactor = 2.5;

std::string Printf(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

}  // namespace

SteadyState Evaluate(const UnitParams& p, bool with_cooling_time) {
  SteadyState r;
  auto created = UnitModel::Create(p);
  if (!created.ok()) return r;
  const UnitModel& m = *created;
  const double stretch = p.prestretch;
  r.h = m.heat_transfer_coefficient();
  r.time_constant = m.time_constant();
  const UnitState on = SettleOn(m, stretch);
  r.on_temperature = on.temperature;
  r.on_xi = on.xi;
  r.on_power = m.HeatingPower(true, on.xi);
  r.on_stress = m.WireStress(m.Tension(on.xi, stretch));
  const double off = m.Tension(1, stretch);
  r.off_stress = m.WireStress(off);
  // The wire's own deflection in martensite (the series spring takes the rest), as a strain:
  // eps_L + sigma / E_M for a straight wire, the same proportion of the coil's deflection.
  const double wire_deflection = m.recoverable_stretch() + off / m.stiffness_martensite();
  r.off_strain = p.eps_L * wire_deflection / m.recoverable_stretch();
  if (with_cooling_time) r.cooling_time = CoolingTime(m, on, stretch);
  return r;
}

SteadyState Evaluate(const BundleConfig& c) { return Evaluate(c.unit); }

double CurrentForTemperature(const UnitParams& p, double t) {
  auto created = UnitModel::Create(p);
  if (!created.ok() || !(t > p.ambient)) return 0;
  const UnitModel& m = *created;
  // Joule power per A^2 in austenite: rho_A L / A; conductance h pi d L.
  const double watts_per_a2 = p.resistivity_A * m.wire_length() / m.area();
  return std::sqrt((t - p.ambient) * m.conductance() / watts_per_a2);
}

std::vector<std::string> DesignWarnings(const BundleConfig& c) {
  std::vector<std::string> w;
  const UnitParams& p = c.unit;
  if (!UnitModel::Create(p).ok()) return w;
  const UnitLimits lim = UnitLimits::ForWire(p.wire_diameter);
  const SteadyState s = Evaluate(p);
  const std::string wire = Printf("%.3g", p.wire_diameter * 1e3) + " mm wire";
  if (s.on_temperature > lim.max_temperature) {
    w.push_back("steady " + Printf("%.0f", s.on_temperature) + " C when on (" + wire + " at " +
                Printf("%.3g", p.current) + " A), above the long-life " +
                Printf("%.0f", lim.max_temperature) + " C: current=" +
                Printf("%.3g", CurrentForTemperature(p, lim.max_temperature)) + " holds it there");
  }
  if (s.peak_stress() > lim.max_wire_stress) {
    w.push_back("wire stress " + Printf("%.0f", s.peak_stress() / 1e6) + " MPa " +
                (s.on_stress >= s.off_stress ? "held on" : "off") +
                " at the reference extension, above Dynalloy's long-life " +
                Printf("%.0f", lim.max_wire_stress / 1e6) + " MPa");
  }
  if (s.cooling_time > kCoolingFactor * lim.cooling_time) {
    std::string t = "cools to 99.5 % relaxed in " + Printf("%.3g", s.cooling_time) + " s, over " +
                    Printf("%.2g", kCoolingFactor) + " times Dynalloy's " +
                    Printf("%.2g", lim.cooling_time) + " s for " + wire;
    w.push_back(t);
  }
  return w;
}

std::string DesignWarning(const BundleConfig& c) {
  const std::vector<std::string> w = DesignWarnings(c);
  if (w.empty()) return "";
  std::string s = "actuator '" + c.actuator + "': ";
  for (size_t i = 0; i < w.size(); ++i) s += (i ? "; " : "") + w[i];
  return s;
}

}  // namespace recruit::sma
