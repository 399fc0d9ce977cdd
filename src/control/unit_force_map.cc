#include "control/unit_force_map.h"

#include <cmath>
#include <string>

namespace recruit::control {

Result<UnitForceMap> UnitForceMap::FromFractions(const UnitGeometry& g, const Eigen::VectorXd& xi) {
  auto unit = sma::UnitModel::Create(g.unit);
  if (!unit) return Error{"unit force map: " + unit.error(), unit.code()};
  if (!std::isfinite(g.ref_length) || g.ref_length <= 0) {
    return Error{"unit force map: ref_length = " + std::to_string(g.ref_length) +
                 " m must be finite and > 0"};
  }
  for (Eigen::Index i = 0; i < xi.size(); ++i) {
    if (!(xi[i] >= 0 && xi[i] <= 1)) {
      return Error{"unit force map: fraction of state " + std::to_string(i) + " = " +
                   std::to_string(xi[i]) + " must be in [0, 1]"};
    }
  }
  return UnitForceMap(std::move(unit).value(), g.ref_length, xi);
}

Result<UnitForceMap> UnitForceMap::FromForces(const UnitGeometry& g, double stretch,
                                              const Eigen::VectorXd& forces) {
  auto unit = sma::UnitModel::Create(g.unit);
  if (!unit) return Error{"unit force map: " + unit.error(), unit.code()};
  if (!std::isfinite(stretch)) return Error{"unit force map: the extension must be finite"};
  Eigen::VectorXd xi(forces.size());
  for (Eigen::Index i = 0; i < forces.size(); ++i) {
    const double f = forces[i];
    if (!std::isfinite(f)) {
      return Error{"unit force map: force of state " + std::to_string(i) + " is not finite"};
    }
    // T(., s) decreases in xi where it is positive: bisection on [0, 1] (60 halvings: exact
    // to round-off, once per model).
    if (f <= 0) {
      xi[i] = 1;
    } else if (f >= unit->Tension(0.0, stretch)) {
      xi[i] = 0;
    } else {
      double lo = 0, hi = 1;  // T(lo) > f >= T(hi)
      for (int k = 0; k < 60; ++k) {
        const double mid = 0.5 * (lo + hi);
        (unit->Tension(mid, stretch) > f ? lo : hi) = mid;
      }
      xi[i] = 0.5 * (lo + hi);
    }
  }
  return FromFractions(g, xi);
}

}  // namespace recruit::control
