// One SMA unit's physics, free of MuJoCo: lumped thermal model, martensite fraction with
// hysteresis (Liang-Rogers cosine major loop, proportional-rule minor loops, stress-shifted
// transformation temperatures) and the unit's tension. plugin/README.md has the equations.
#pragma once

#include <string>

#include "common/result.h"
#include "plugin/unit_batch.h"

namespace recruit::sma {

enum class ForceLaw { kWire, kSpring };

// Parameters of one unit (immutable). SI units, temperatures in deg C, stresses in Pa.
struct UnitParams {
  // Material (NiTi, Flexinol-like; sources in plugin/README.md).
  double density = 6450;                      // kg/m^3
  double specific_heat = 837;                 // J/(kg K)
  double latent_heat = 24200;                 // J/kg (Dynalloy); 0 = off
  double resistivity_M = 80e-8;               // ohm m, martensite
  double resistivity_A = 100e-8;              // ohm m, austenite
  double As = 68, Af = 78, Ms = 52, Mf = 42;  // transformation temperatures at zero stress, C
  double C_A = 10.3e6, C_M = 10.3e6;          // stress-temperature slopes, Pa/K
  double E_A = 75e9, E_M = 28e9;              // Young's moduli, Pa (wire law)
  double G_A = 28e9, G_M = 10.5e9;            // shear moduli, Pa (spring law)
  double eps_L = 0.04;                        // recoverable strain
  // Geometry. Defaults (docs/sma-units.md has the numbers and the limit check): a straight
  // 0.1 mm Flexinol-type LT wire, 100 mm long, in series with a 114 N/m coupling spring, taken
  // up by 4 mm (= eps_L * wire_length, so the unit is just taut in martensite), heated at
  // 0.18 A. Steady on-temperature about 116 C (Af = 78 C), settled isometric force 0.447 N
  // per unit (26.8 N for 60: the paper's Fig. 4) at 57 MPa wire stress (Dynalloy rates 172 MPa
  // for long life), current 90 % of Dynalloy's 200 mA "1 s contraction" value for 0.1 mm,
  // thermal time constant 0.98 s against Dynalloy's 1.1 s cooling time. A 0.1 mm wire coiled to
  // 0.33 mm that gives Fig. 4 at 0.235 A runs at 171 C and ~1 GPa (docs/sma-units.md).
  ForceLaw law = ForceLaw::kWire;
  double wire_diameter = 0.1e-3;   // m
  double wire_length = 0.1;        // m, wire law only (a spring's wire is pi * D * turns long)
  double coil_diameter = 0.33e-3;  // m (spring law: mean coil diameter)
  double turns = 20;               // active turns (spring law)
  double prestretch = 4e-3;        // m: the whole unit's extension at the reference tendon length
  // Elastic element in series with each wire (a coupling spring, N/m per segment; 0 = rigid).
  // It makes a straight wire's isometric force grow across the transformation instead of jumping.
  double series_spring = 114;
  // Unit made of `series` segments in series (each takes stretch / series: stroke multiplies)
  // of `parallel` identical wires each (the unit's tension is parallel * one wire's: force
  // multiplies). Every wire carries `current` and has the same temperature.
  int series = 1;
  int parallel = 1;
  // Thermal and electrical.
  double current = 0.18;    // A per wire, heating current when on
  double ambient = 20;      // C
  double h = 0;             // W/(m^2 K); 0 = from the natural-convection correlation
  double emissivity = 0.3;  // for the linearised radiation term added to h
};

// Datasheet limits for one wire (Dynalloy Flexinol, technical characteristics F1140 and its
// wire table; docs/sma-units.md): what a run loop compares MaxTemperature / MaxWireStress with.
struct UnitLimits {
  double max_wire_stress = 172e6;  // Pa: Dynalloy's rated pull stress for long cycle life
  // C: steady wire temperature an LT (As 68 C, Af 78 C) wire should not exceed: about 40 K
  // above Af; hotter only costs power and cooling time and ages the alloy.
  double max_temperature = 120;
  double max_current = 0.2;   // A: Dynalloy's current for a 1 s contraction (0.1 mm wire)
  double cooling_time = 1.1;  // s: Dynalloy's still-air cooling time, LT wire (0.1 mm wire)

  // The defaults with max_current and cooling_time from Dynalloy's table for diameter d (m),
  // log-log interpolated between the stock sizes 0.025 to 0.51 mm (clamped outside).
  static UnitLimits ForWire(double d);
};

// Quantities derived once from UnitParams, used in every step.
class UnitModel {
 public:
  static Result<UnitModel> Create(const UnitParams& p);

  const UnitParams& params() const { return p_; }

  // Martensite fraction on the major heating curve M+ (1 below As, 0 above Af) and on the major
  // cooling curve M- (1 below Mf, 0 above Ms), as functions of the effective temperature.
  double MajorHeating(double t_eff) const;
  double MajorCooling(double t_eff) const;

  // The same with their derivatives with respect to t_eff (<= 0) in *slope.
  double MajorHeating(double t_eff, double* slope) const;
  double MajorCooling(double t_eff, double* slope) const;

  // Tension of one unit (N, >= 0) at fraction xi and extension `stretch` (m), and its
  // derivative with respect to xi.
  double Tension(double xi, double stretch) const;
  double TensionSlope(double xi, double stretch) const;
  double Tension(double xi, double stretch, double* slope) const;  // both at once
  // Equivalent tensile stress (Pa) that shifts the transformation temperatures at tension f.
  double Stress(double f) const { return stress_per_newton_ * f; }
  // Stress in one wire when the unit pulls with tension f (N): true tensile stress
  // f / (parallel A) for the wire law, the Wahl-corrected equivalent sqrt(3) tau for a spring.
  // The same number as Stress(f); named for checks against the datasheet's rated stress.
  double WireStress(double f) const { return Stress(f); }

  // Lumped thermal model with constant power over dt, integrated exactly.
  double HeatingPower(bool on, double xi) const;       // W
  double SteadyTemperature(bool on, double xi) const;  // C
  double ThermalStep(double t, bool on, double xi, double dt) const;
  double DecayFactor(double dt) const;  // exp(-dt / tau)

  double heat_transfer_coefficient() const { return h_; }    // W/(m^2 K), used value
  double time_constant() const { return tau_; }              // s
  double heat_capacity() const { return heat_capacity_; }    // J/K of one wire
  double conductance() const { return conductance_; }        // W/K = h A_s of one wire
  double area() const { return area_; }                      // wire cross-section, m^2
  double wire_length() const { return length_; }             // m, one wire (pi D n for a spring)
  double stiffness_austenite() const { return k_A_; }        // N/m
  double stiffness_martensite() const { return k_M_; }       // N/m
  double recoverable_stretch() const { return stretch_L_; }  // m (whole unit: series segments)
  double series_stiffness() const { return k_s_; }           // N/m of the unit, 0 = rigid
  // Hottest steady temperature when on (austenite resistivity): the "heat = 1" point.
  double on_temperature() const { return SteadyTemperature(true, 0.0); }

  // Constants of the per-step phase solve, derived once.
  double latent_rise() const { return latent_rise_; }  // K of temperature per unit of xi (L / c)
  // K of T_eff shift per N of unit tension on heating (C_A) and cooling (C_M).
  double heat_shift_per_newton() const { return heat_shift_per_newton_; }
  double cool_shift_per_newton() const { return cool_shift_per_newton_; }

  // Advances n cohorts (structure of arrays, one entry per cohort) by one step with thermal decay
  // factor `decay` at extension `stretch`: lane by lane the same operations as
  // AdvanceUnitWithDecay, so the results are bit-identical to it (test
  // BatchedCohortUpdateIsBitIdenticalToScalarUpdate), but four cohorts at a time in SIMD lanes,
  // the phase solves of the transforming cohorts gathered into full batches (unit_batch.cc).
  struct Cohorts {
    const double* on;  // 0 or 1
    double* temperature;
    double* xi;
    double* t_eff;
    double* heat_scale;
    double* cool_scale;
  };
  // Kernel: kAuto = AVX-512 (8 lanes) for the update of more than four cohorts (AVX2 for up to
  // four) and AVX2 for the sums when this build has those clones and the CPU runs them, else
  // AVX2, else the build's own instruction set (kBase).
  // kAvx512 uses AVX2 for the sums. Tests run each.
  enum class Isa { kAuto, kBase, kAvx2, kAvx512 };
  // With `obs` (count and stretch set) the update also gives the updated cohorts' telemetry
  // (BatchObserve: SumTelemetry's five values with the peak, bit for bit, and the largest
  // temperature), from its registers when they fit two SIMD blocks (one cohort: from the scalar
  // update's values); otherwise obs->done stays false and the caller sums.
  void AdvanceCohorts(const Cohorts& c, int n, double stretch, double decay, Isa isa = Isa::kAuto,
                      BatchObserve* obs = nullptr) const;
  // Sum over n cohorts of count[j] * Tension(xi[j], stretch), in SIMD lanes.
  double SumTension(const double* count, const double* xi, int n, double stretch,
                    Isa isa = Isa::kAuto) const;
  // Sets out[f] = sum over j < n of count[j] * v[f][j] for f < nf <= 3, in four partial sums
  // (s0 + s1) + (s2 + s3) of cohorts j mod 4: exact for one cohort.
  static void WeightedSums(const double* count, const double* const* v, int nf, int n, double* out);
  // WeightedSums of v[0..2] (on, temperature, xi) and SumTension of xi = v[2] in one pass, each
  // bit for bit the value those give, in out[0..3]; with `peak` also out[4] = the largest
  // Tension(xi[j], stretch) over the cohorts (0 for none).
  void SumTelemetry(const double* count, const double* const* v, int n, double stretch, bool peak,
                    double* out, Isa isa = Isa::kAuto) const;
  // The cohorts' order by (on, temperature) for the merge pass, without branches on the data:
  // when no two keys tie (and on is 0 or 1, no temperature NaN) that order is unique, so it is
  // std::sort's; order[p] = the cohort at position p. False (order unspecified) otherwise: the
  // caller sorts. Scratch: t and idx 2 (n + 8) entries each.
  static bool MergeOrder(const double* on, const double* temp, int n, int* order, double* t,
                         int* idx, Isa isa = Isa::kAuto);
  // idx[i] = remap[idx[i]] for i < n (cohort indices of units, held as doubles).
  static void Relabel(double* idx, int n, const int* remap);
  // Whether kAvx2 is available (built and supported by the CPU); the lanes kAuto uses.
  static bool HasAvx2();
  static bool HasAvx512();  // the AVX-512 update (F and DQ): built and supported
  static int Lanes(Isa isa = Isa::kAuto);

  // Natural convection (Morgan's horizontal-cylinder correlation, air at the film temperature)
  // plus linearised radiation, for a wire of diameter d at temperature excess dT over ambient.
  static double NaturalConvectionH(double d, double ambient, double dT, double emissivity);

 private:
  UnitParams p_;
  double area_ = 0, length_ = 0, h_ = 0, heat_capacity_ = 0, conductance_ = 0, tau_ = 0;
  double k_A_ = 0, k_M_ = 0, stretch_L_ = 0;  // unit stiffness (N/m) and recoverable stretch (m)
  double k_s_ = 0;                            // series spring of the unit (N/m), 0 = rigid
  // Unit stiffness at xi (wire in series with the coupling spring) and its xi-derivative.
  double Stiffness(double xi, double* dk) const;
  // AdvanceCohorts' update; the kernel may fill `obs` (then obs->done).
  void Update(const Cohorts& c, int n, double stretch, double decay, Isa isa,
              BatchObserve* obs) const;
  double stress_per_newton_ = 0;
  double heat_rate_ = 0, cool_rate_ = 0;  // pi / (Af - As), pi / (Ms - Mf)
  double latent_rise_ = 0, heat_shift_per_newton_ = 0, cool_shift_per_newton_ = 0;
  double on_power_A_ = 0, on_power_dM_ = 0;  // Joule power (W) in austenite; M minus A
  double on_rise_A_ = 0, on_rise_dM_ = 0;    // the same over the conductance (K)
  BatchParams batch_{};  // the constants above as the batched kernels take them (Create)
};

// sin and cos of an angle a in [0, pi] (the cosine curves' range), as a polynomial: with
// b = a - pi/2 in [-pi/2, pi/2], sin a = cos b and cos a = -sin b by their Taylor series to
// b^20 and b^19. The truncation error is below (pi/2)^21 / 21! < 3e-16 and the rounding error a
// few ulp, so both are within 1e-15 of the exact values (test
// PolynomialSinCosMatchesLibmOverTheHalfTurn); the phase solve's tolerances are 1e-13 and above.
// Inlined, 64 instructions against about 94 for glibc's sincos call (callgrind). T is double or
// a GCC vector of doubles (the batched cohort update): the same operations lane by lane.
template <class T>
inline void SinCosHalfTurn(T a, T* sin_a, T* cos_a) {
  const T b = a - 0.5 * 3.14159265358979323846;
  const T z = b * b, z2 = z * z, z4 = z2 * z2, z8 = z4 * z4;
  // Taylor coefficients (-1)^k / (2k)! (cosine) and (-1)^k / (2k+1)! (sine) of z^k, k = 0..10
  // and 0..9, summed by Estrin's scheme (shorter dependency chains than Horner's).
  constexpr double c0 = 1, c1 = -1.0 / 2, c2 = 1.0 / 24, c3 = -1.0 / 720, c4 = 1.0 / 40320,
                   c5 = -1.0 / 3628800, c6 = 1.0 / 479001600, c7 = -1.0 / 87178291200,
                   c8 = 1.0 / 20922789888000, c9 = -1.0 / 6402373705728000,
                   c10 = 1.0 / 2432902008176640000;
  constexpr double s0 = 1, s1 = -1.0 / 6, s2 = 1.0 / 120, s3 = -1.0 / 5040, s4 = 1.0 / 362880,
                   s5 = -1.0 / 39916800, s6 = 1.0 / 6227020800, s7 = -1.0 / 1307674368000,
                   s8 = 1.0 / 355687428096000, s9 = -1.0 / 121645100408832000;
  const T cos_b = ((c0 + c1 * z) + (c2 + c3 * z) * z2) + ((c4 + c5 * z) + (c6 + c7 * z) * z2) * z4 +
                  ((c8 + c9 * z) + c10 * z2) * z8;
  const T sin_b = b * (((s0 + s1 * z) + (s2 + s3 * z) * z2) +
                       ((s4 + s5 * z) + (s6 + s7 * z) * z2) * z4 + (s8 + s9 * z) * z8);
  *sin_a = cos_b;
  *cos_a = -sin_b;
}

// State of one unit (or of a cohort of identical units).
struct UnitState {
  double temperature = 20;  // C
  double xi = 1;            // martensite fraction: 1 relaxed, 0 contracted
  double t_eff = 20;        // effective temperature T - sigma / C at the last step (for reversals)
  // Proportional-rule branch constants: heating follows xi = heat_scale * M+(T_eff), cooling
  // follows 1 - xi = cool_scale * (1 - M-(T_eff)). Each is reset where the opposite branch last
  // transformed, so a reversal without transformation (e.g. a short cool above Ms) does not
  // shift the next branch.
  double heat_scale = 1;
  double cool_scale = 0;
};

// Cold, relaxed martensite at ambient, unloaded at `stretch`.
UnitState RestState(const UnitModel& m, double stretch);

// Advances one unit by dt: exact thermal step at the power of the current phase, then the phase
// fraction solved implicitly (with latent heat folded into the residual) at the new temperature
// and the given extension. Heating and cooling follow the proportional rule, so a reversal starts
// a minor loop inside the major loop.
void AdvanceUnit(const UnitModel& m, UnitState& s, bool on, double stretch, double dt);
// Sets the unit's temperature to t (as if imposed from outside) and solves the phase fraction
// at extension `stretch`, with the same hysteresis rules (and latent heat) as AdvanceUnit.
void ImposeTemperature(const UnitModel& m, UnitState& s, double t, double stretch);
// The same with the thermal decay factor exp(-dt / tau) precomputed by the caller.
void AdvanceUnitWithDecay(const UnitModel& m, UnitState& s, bool on, double stretch, double decay);

}  // namespace recruit::sma
