// UnitForceMap: the force one unit pulls in each state of an estimator's model as a function of
// the tendon's length (docs/identification.md, "Length-dependent output").
//
// A unit's tension is the plugin's force law, T(xi, s) = k(xi) (s - xi s_L)+ (plugin/README.md):
// xi its martensite fraction, s its extension, which follows the tendon one for one,
// s = prestretch + (L - ref_length). Each model state is given an effective fraction xi_i, so
//   h_i(L) = T(xi_i, s(L)) >= 0.
// While the limb moves a unit keeps its fraction (the phase changes with temperature, slowly), so
// its force follows the tendon through T at that fraction: this is what a fixed H cannot do (a hot
// flexor unit of the elbow arm pulls 0.45 N at 0 deg and 0.27 N at 70 deg). The fractions are
// found from the forces a model was identified with at one extension (FromForces), where every
// state whose fraction is below s / s_L is taut, so identification is done at the longest tendon
// length of the working range (identification/bench_recorder.h).
#pragma once

#include <Eigen/Core>

#include "common/result.h"
#include "plugin/unit_model.h"

namespace recruit::control {

// What of a bundle's configuration the map needs (plugin config keys; plugin/README.md).
struct UnitGeometry {
  sma::UnitParams unit;   // its prestretch is the extension at ref_length
  double ref_length = 0;  // m, tendon length at which the unit's extension is unit.prestretch
};

class UnitForceMap {
 public:
  // Fractions in [0, 1], one per state.
  static Result<UnitForceMap> FromFractions(const UnitGeometry& g, const Eigen::VectorXd& xi);
  // The fractions whose tension at extension `stretch` (m) is `forces` (N per unit): the inverse
  // of T(., stretch), clamped to [0, 1]. A force at or below zero maps to xi = 1 (cold
  // martensite; a slack unit's fraction is not seen at this extension).
  static Result<UnitForceMap> FromForces(const UnitGeometry& g, double stretch,
                                         const Eigen::VectorXd& forces);

  int num_states() const { return static_cast<int>(xi_.size()); }
  const Eigen::VectorXd& fractions() const { return xi_; }
  const sma::UnitModel& unit() const { return unit_; }
  double Stretch(double tendon_length) const { return prestretch_ + (tendon_length - ref_length_); }
  // h_i(L) for every state, into h (num_states entries).
  template <class Row>
  void Forces(double tendon_length, Row& h) const {
    const double s = Stretch(tendon_length);
    for (int i = 0; i < num_states(); ++i) h[i] = unit_.Tension(xi_[i], s);
  }
  double Force(int state, double tendon_length) const {
    return unit_.Tension(xi_[state], Stretch(tendon_length));
  }

 private:
  UnitForceMap(sma::UnitModel unit, double ref_length, Eigen::VectorXd xi)
      : unit_(std::move(unit)),
        ref_length_(ref_length),
        prestretch_(unit_.params().prestretch),
        xi_(std::move(xi)) {}

  sma::UnitModel unit_;
  double ref_length_ = 0, prestretch_ = 0;
  Eigen::VectorXd xi_;
};

}  // namespace recruit::control
