#include "identification/settled_fraction.h"

#include <cmath>

namespace recruit::identification {

namespace {

// Steps of tau / 10 with the heater `on` until the fraction changes by less than 1e-12 over a
// time constant (at least 40 of them, at most 4000): near a partial transformation the phase and
// the temperature drift together slowly (an underheated unit took 800 tau to settle).
void Settle(const sma::UnitModel& unit, sma::UnitState& st, bool on, double stretch) {
  const double decay = unit.DecayFactor(unit.time_constant() / 10);
  for (int tau = 0; tau < 4000; ++tau) {
    const double before = st.xi;
    for (int i = 0; i < 10; ++i) sma::AdvanceUnitWithDecay(unit, st, on, stretch, decay);
    if (tau >= 40 && std::abs(st.xi - before) < 1e-12) return;
  }
}

}  // namespace

double SettledFraction(const sma::UnitModel& unit, double stretch, bool on) {
  sma::UnitState st = sma::RestState(unit, stretch);
  Settle(unit, st, true, stretch);
  if (!on) Settle(unit, st, false, stretch);
  return st.xi;
}

double SettledStateFraction(const sma::UnitModel& unit, const std::vector<double>& stretches,
                            bool on) {
  std::vector<double> target;
  for (double s : stretches) target.push_back(unit.Tension(SettledFraction(unit, s, on), s));
  auto cost = [&](double xi) {
    double c = 0;
    for (size_t k = 0; k < stretches.size(); ++k) {
      const double e = unit.Tension(xi, stretches[k]) - target[k];
      c += e * e;
    }
    return c;
  };
  // T(xi, s) is monotone in xi, so the cost is unimodal on [0, 1].
  double a = 0, b = 1;
  const double g = (std::sqrt(5.0) - 1) / 2;
  double x1 = b - g * (b - a), x2 = a + g * (b - a), f1 = cost(x1), f2 = cost(x2);
  for (int it = 0; it < 80 && b - a > 1e-12; ++it) {
    if (f1 < f2) {
      b = x2, x2 = x1, f2 = f1, x1 = b - g * (b - a), f1 = cost(x1);
    } else {
      a = x1, x1 = x2, f1 = f2, x2 = a + g * (b - a), f2 = cost(x2);
    }
  }
  // The bounds themselves (a fully transformed unit sits at 0 or 1 exactly).
  double best = (a + b) / 2, fbest = cost(best);
  for (double edge : {0.0, 1.0}) {
    if (cost(edge) <= fbest) best = edge, fbest = cost(edge);
  }
  return best;
}

}  // namespace recruit::identification
