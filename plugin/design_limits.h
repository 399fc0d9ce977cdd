// Design limits of one SMA unit, free of MuJoCo: the steady state a configuration leads to (from
// the unit physics of unit_model.h), the alloy's domain (BundleConfig refuses a configuration
// whose steady state leaves it) and the datasheet's long-life limits (one warning when a model
// loads). plugin/README.md, "Limits", gives every number and its source.
#pragma once

#include <string>
#include <vector>

#include "plugin/bundle_config.h"
#include "plugin/unit_model.h"

namespace recruit::sma {

// The alloy's domain. Beyond these the wire stops being a shape-memory actuator.
struct AlloyDomain {
  // C: steady wire temperature. Heat treatments of 300-550 C change NiTi's transformation
  // temperatures (precipitation, annealing; recrystallisation from about 450 C) and shape setting
  // is done at 500-550 C: a wire held there loses its trained memory.
  static constexpr double kMaxTemperature = 300;
  // Pa: yield strength of NiTi's martensite after the transformation (Special Metals, SMC-017:
  // 814 MPa): above it the wire deforms plastically and the strain is not recovered.
  static constexpr double kMaxStress = 814e6;
  // Recoverable (transformation) strain of polycrystalline NiTi: at most 8 % for a single cycle
  // (SMA Inc., NiTi Smart Sheet; Special Metals SMC-017).
  static constexpr double kMaxStrain = 0.08;
  // Shortest wire, in wire diameters: heat conducts into the terminals over the conduction
  // length sqrt(k d / (4 h)), 12-18 d for 0.5-0.1 mm wire in still air (k = 18 W/(m K)); a wire
  // shorter than 20 d is held near its terminals' temperature all along, which the lumped
  // thermal model does not describe.
  static constexpr double kMinLengthPerDiameter = 20;
};

// The steady state of one unit of a configuration, at its reference extension `prestretch` (a
// configuration knows no tendon range: the plugin's fit check covers the tendon's excursion).
struct SteadyState {
  double h = 0;               // W/(m^2 K), the heat transfer coefficient used
  double time_constant = 0;   // s, rho c d / (4 h)
  double on_temperature = 0;  // C: a unit held on, settled (T_amb + I^2 R / (h A_s))
  double on_xi = 1;           // martensite fraction held on, settled (0 = fully contracted)
  double on_power = 0;        // W per wire held on, settled
  double on_stress = 0;       // Pa: wire stress held on, settled
  double off_stress = 0;      // Pa: wire stress off (cold martensite)
  double off_strain = 0;      // wire strain off: eps_L + elastic strain when taut
  // s: from the settled on state, switched off, until the unit is 99.5 % relaxed (xi >= 0.995,
  // i.e. its temperature below about Mf; Dynalloy's cooling times leave out the last 0.5 %);
  // infinity when it never relaxes (ambient too warm for the martensite to return).
  double cooling_time = 0;
  double peak_stress() const { return on_stress > off_stress ? on_stress : off_stress; }
};

// The steady state of `p` (the defaults above when UnitModel::Create refuses it). Without
// `with_cooling_time` cooling_time stays 0 (the refusal check at every load skips it).
SteadyState Evaluate(const UnitParams& p, bool with_cooling_time = true);
SteadyState Evaluate(const BundleConfig& c);

// Current (A per wire) whose steady temperature when on, in austenite, is t (C): the inverse of
// T_ss = T_amb + I^2 rho_A L / (A h A_s) at the model's h. 0 when t is not above ambient.
double CurrentForTemperature(const UnitParams& p, double t);

// The long-life limits of c's wire (UnitLimits::ForWire: 120 C, 172 MPa, Dynalloy's cooling time
// for its diameter) that its steady state exceeds, one text each, e.g. "steady 211 C when on
// (0.15 mm wire at 0.4 A), above the long-life 120 C: current=0.289 holds it there". Empty when
// none is exceeded.
// The model cools the default unit 2.2 times slower than Dynalloy's table says, so a cooling
// time counts as exceeded above 2.5 times the datasheet's.
std::vector<std::string> DesignWarnings(const BundleConfig& c);
// The one load-time warning: "actuator 'NAME': " and the texts of DesignWarnings joined by "; ",
// or "" when there are none.
std::string DesignWarning(const BundleConfig& c);

}  // namespace recruit::sma
