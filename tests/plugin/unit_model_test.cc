// Unit physics without MuJoCo, against hand-written closed forms (plugin/README.md, equations
// restated here independently of plugin/unit_model.cc).
#include "plugin/unit_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace recruit::sma {
namespace file_unit_model_test {

constexpr double kPi = 3.14159265358979323846;

UnitModel MakeModel(const UnitParams& p) {
  auto m = UnitModel::Create(p);
  EXPECT_TRUE(m.ok()) << m.error();
  return m.value();
}

// Major loop of the Liang-Rogers cosine model at zero stress.
double MajorHeatingRef(double t) {  // As = 68, Af = 78
  if (t <= 68) return 1;
  if (t >= 78) return 0;
  return 0.5 * (std::cos(kPi * (t - 68) / 10) + 1);
}
double MajorCoolingRef(double t) {  // Mf = 42, Ms = 52
  if (t <= 42) return 1;
  if (t >= 52) return 0;
  return 0.5 * (std::cos(kPi * (t - 42) / 10) + 1);
}

// The previous default unit: 0.1 mm wire coiled to 0.33 mm, 20 turns, no coupling spring.
UnitParams Coil() {
  UnitParams p;
  p.law = ForceLaw::kSpring;
  p.series_spring = 0;
  p.prestretch = 3e-3;
  return p;
}

// Unloaded quasi-static unit: zero extension gives zero tension at any xi, so T_eff = T.
UnitParams Unloaded() {
  UnitParams p;
  p.prestretch = 0;
  p.latent_heat = 0;
  return p;
}

TEST(UnitThermal, HeatingStepMatchesClosedForm) {
  UnitParams p = Unloaded();
  p.law = ForceLaw::kWire;
  p.wire_diameter = 0.1e-3;
  p.h = 100;
  p.current = 0.05;  // steady temperature stays below As: xi stays 1, resistance constant
  const UnitModel m = MakeModel(p);
  // Closed form: tau = rho c d / (4 h); T_ss = T_amb + I^2 rho_M 4 / (pi d^2) / (h pi d).
  const double d = p.wire_diameter;
  const double tau = 6450.0 * 837.0 * d / (4 * 100.0);
  const double t_ss = 20 + 0.05 * 0.05 * 80e-8 * 4 / (kPi * d * d) / (100.0 * kPi * d);
  ASSERT_LT(t_ss, 68);
  UnitState s = RestState(m, 0);
  for (int i = 1; i <= 3000; ++i) {
    AdvanceUnit(m, s, true, 0, 1e-3);
    if (i % 500 == 0) {
      const double t = i * 1e-3;
      EXPECT_NEAR(s.temperature, t_ss + (20 - t_ss) * std::exp(-t / tau), 1e-9) << "t=" << t;
    }
  }
  EXPECT_DOUBLE_EQ(s.xi, 1.0);
  EXPECT_NEAR(m.time_constant(), tau, 1e-12);
}

TEST(UnitThermal, HotUnloadedUnitSettlesAtJouleOverConvectionTemperature) {
  // Unloaded, so fully austenite once hot: T_ss = T_amb + I^2 rho_A L / A / (h pi d L).
  UnitParams p = Unloaded();
  p.law = ForceLaw::kWire;
  p.h = 120;
  p.current = 0.2;
  const UnitModel m = MakeModel(p);
  const double d = p.wire_diameter;
  const double t_ss = 20 + 0.2 * 0.2 * 100e-8 * 4 / (kPi * d * d) / (120.0 * kPi * d);
  ASSERT_GT(t_ss, 90);
  UnitState s = RestState(m, 0);
  for (int i = 0; i < 40000; ++i) AdvanceUnit(m, s, true, 0, 1e-3);  // 36 tau
  EXPECT_EQ(s.xi, 0.0);
  EXPECT_NEAR(s.temperature, t_ss, 1e-6);
  EXPECT_NEAR(m.on_temperature(), t_ss, 1e-9);
}

TEST(UnitThermal, CoolingStepMatchesClosedFormAndIsStableForLargeSteps) {
  UnitParams p = Unloaded();
  p.h = 120;
  const UnitModel m = MakeModel(p);
  UnitState s = RestState(m, 0);
  s.temperature = 60;  // above ambient, below As: no transformation either way
  const double tau = m.time_constant();
  AdvanceUnit(m, s, false, 0, 0.5);
  EXPECT_NEAR(s.temperature, 20 + 40 * std::exp(-0.5 / tau), 1e-9);
  // A step of 100 tau lands on ambient, no overshoot (exact exponential integration).
  AdvanceUnit(m, s, false, 0, 100 * tau);
  EXPECT_NEAR(s.temperature, 20, 1e-9);
}

TEST(UnitThermal, NaturalConvectionMatchesPublishedCoolingTimes) {
  // SMA-NOTES / Dynalloy: tau about 1.0 s for 0.10 mm wire and 4.3 s for 0.25 mm.
  for (auto [d, tau_ref] : {std::pair{0.10e-3, 1.0}, std::pair{0.25e-3, 4.3}}) {
    const double h = UnitModel::NaturalConvectionH(d, 20, 53, 0.3);
    const double tau = 6450.0 * 837.0 * d / (4 * h);
    EXPECT_NEAR(tau, tau_ref, 0.25 * tau_ref) << "d=" << d << " h=" << h;
  }
}

TEST(UnitHysteresis, MajorLoopFollowsCosineCurvesAndCloses) {
  const UnitModel m = MakeModel(Unloaded());
  UnitState s = RestState(m, 0);
  for (double t = 20; t <= 100; t += 0.25) {
    ImposeTemperature(m, s, t, 0);
    ASSERT_NEAR(s.xi, MajorHeatingRef(t), 1e-9) << "heating, T=" << t;
  }
  for (double t = 100; t >= 20; t -= 0.25) {
    ImposeTemperature(m, s, t, 0);
    ASSERT_NEAR(s.xi, MajorCoolingRef(t), 1e-9) << "cooling, T=" << t;
  }
  EXPECT_EQ(s.xi, 1.0);  // the loop closes
}

TEST(UnitHysteresis, MinorLoopsFollowProportionalRuleInsideMajorLoop) {
  const UnitModel m = MakeModel(Unloaded());
  UnitState s = RestState(m, 0);
  for (double t = 20; t <= 73; t += 0.5) ImposeTemperature(m, s, t, 0);
  const double xi_r = MajorHeatingRef(73);
  ASSERT_NEAR(s.xi, xi_r, 1e-9);
  // Cooling from the reversal: 1 - xi = (1 - xi_r) (1 - M-(T)).
  for (double t = 73; t >= 46; t -= 0.5) {
    ImposeTemperature(m, s, t, 0);
    ASSERT_NEAR(s.xi, 1 - (1 - xi_r) * (1 - MajorCoolingRef(t)), 1e-9) << "T=" << t;
  }
  const double xi_c = s.xi;
  // Reheating: xi = xi_c M+(T) (M+ = 1 at the reversal, 46 C < As).
  for (double t = 46; t <= 75; t += 0.5) {
    ImposeTemperature(m, s, t, 0);
    ASSERT_NEAR(s.xi, xi_c * MajorHeatingRef(t), 1e-9) << "T=" << t;
    ASSERT_LE(s.xi, MajorHeatingRef(t) + 1e-12);
    ASSERT_GE(s.xi, MajorCoolingRef(t) - 1e-12);
  }
}

TEST(UnitHysteresis, RepeatedMinorCyclesConvergeToClosedLoopInsideMajorLoop) {
  const UnitModel m = MakeModel(Unloaded());
  UnitState s = RestState(m, 0);
  double prev_hot = -1, prev_cold = -1, hot = 0, cold = 0;
  for (int cycle = 0; cycle < 40; ++cycle) {
    for (double t = 46; t <= 74; t += 0.5) {
      ImposeTemperature(m, s, t, 0);
      ASSERT_GE(s.xi, 0.0);
      ASSERT_LE(s.xi, MajorHeatingRef(t) + 1e-12);
      ASSERT_GE(s.xi, MajorCoolingRef(t) - 1e-12);
    }
    hot = s.xi;
    for (double t = 74; t >= 46; t -= 0.5) {
      ImposeTemperature(m, s, t, 0);
      ASSERT_LE(s.xi, 1.0);
      ASSERT_LE(s.xi, MajorHeatingRef(t) + 1e-12);
      ASSERT_GE(s.xi, MajorCoolingRef(t) - 1e-12);
    }
    cold = s.xi;
    if (cycle == 39) {
      EXPECT_NEAR(hot, prev_hot, 1e-9);
      EXPECT_NEAR(cold, prev_cold, 1e-9);
    }
    prev_hot = hot;
    prev_cold = cold;
  }
  EXPECT_LT(hot, cold);  // a loop with width, not a line
}

TEST(UnitHysteresis, CoolingAboveMsAndReheatingDoesNotTransformAgain) {
  const UnitModel m = MakeModel(Unloaded());
  UnitState s = RestState(m, 0);
  for (double t = 20; t <= 73; t += 0.5) ImposeTemperature(m, s, t, 0);
  const double xi_r = s.xi;
  for (int k = 0; k < 5; ++k) {
    for (double t = 73; t >= 55; t -= 0.5) ImposeTemperature(m, s, t, 0);  // Ms = 52
    EXPECT_DOUBLE_EQ(s.xi, xi_r);
    for (double t = 55; t <= 73; t += 0.5) ImposeTemperature(m, s, t, 0);
    EXPECT_NEAR(s.xi, xi_r, 1e-12);
  }
}

TEST(UnitHysteresis, StressShiftsTransformationByStressOverC) {
  // A blocked spring: the solved state satisfies xi = M+(T - sigma(xi) / C_A), with sigma from
  // the spring formulas written out here.
  UnitParams p = Coil();
  p.latent_heat = 0;
  const UnitModel m = MakeModel(p);
  const double d = p.wire_diameter, D = p.coil_diameter, n = p.turns;
  const double geom = std::pow(d, 4) / (8 * D * D * D * n);
  const double stretch_l = kPi * n * D * D * std::sqrt(3.0) * p.eps_L / d;
  const double index = D / d;
  const double wahl = (4 * index - 1) / (4 * index - 4) + 0.615 / index;
  UnitState s = RestState(m, p.prestretch);
  for (double t = 20; t <= 160; t += 1) {
    ImposeTemperature(m, s, t, p.prestretch);
    const double k = p.G_A * geom + s.xi * (p.G_M - p.G_A) * geom;
    const double f = std::max(0.0, k * (p.prestretch - s.xi * stretch_l));
    const double sigma = std::sqrt(3.0) * 8 * f * D * wahl / (kPi * d * d * d);
    const double t_eff = t - sigma / p.C_A;
    ASSERT_NEAR(s.xi, MajorHeatingRef(t_eff), 1e-9) << "T=" << t;
    ASSERT_NEAR(m.Tension(s.xi, p.prestretch), f, 1e-9);
  }
  // The force is held back by the stress: at 160 C the unit is still partly martensite.
  EXPECT_GT(s.xi, 0.0);
}

TEST(UnitHysteresis, BlockedWireHeatsWithoutOscillation) {
  // Loop gain E eps_L / (C (Af - As)) is about 29 here: an explicit lag would oscillate.
  UnitParams p;
  p.law = ForceLaw::kWire;
  p.wire_diameter = 0.05e-3;
  p.prestretch = 0.01 * p.wire_length;
  p.current = 0.1;
  const UnitModel m = MakeModel(p);
  UnitState s = RestState(m, p.prestretch);
  double prev_xi = s.xi, prev_f = 0;
  for (int i = 0; i < 5000; ++i) {
    AdvanceUnit(m, s, true, p.prestretch, 1e-3);
    const double f = m.Tension(s.xi, p.prestretch);
    ASSERT_LE(s.xi, prev_xi + 1e-15) << "step " << i;
    ASSERT_GE(f, prev_f - 1e-12) << "step " << i;
    ASSERT_GE(s.xi, 0.0);
    prev_xi = s.xi;
    prev_f = f;
  }
  EXPECT_GT(prev_f, 0.1);
}

TEST(UnitHysteresis, LatentHeatIsAbsorbedByTheTransformation) {
  UnitParams p = Unloaded();
  p.latent_heat = 24200;
  const UnitModel m = MakeModel(p);
  UnitState s = RestState(m, 0);
  ImposeTemperature(m, s, 67.9, 0);
  ASSERT_EQ(s.xi, 1.0);
  // Impose 74 C: xi must satisfy xi = M+(74 + L/c (xi - 1)), T = 74 + L/c (xi - 1).
  ImposeTemperature(m, s, 74, 0);
  const double lc = 24200.0 / 837.0;
  EXPECT_NEAR(s.temperature, 74 + lc * (s.xi - 1), 1e-9);
  EXPECT_NEAR(s.xi, MajorHeatingRef(s.temperature), 1e-9);
  EXPECT_GT(s.xi, MajorHeatingRef(74));  // less transformed than without latent heat
}

// Phase fraction after one step by bisection on the residual of plugin/README.md with libm's
// cosine, to the last bit: the reference for the fast solver (Newton, polynomial sincos).
struct RefStep {
  double xi;
  bool heating;
};
RefStep ReferencePhaseStep(const UnitModel& m, const UnitState& s, bool on, double stretch,
                           double dt) {
  const UnitParams& p = m.params();
  const double rho = p.resistivity_A + s.xi * (p.resistivity_M - p.resistivity_A);
  const double power = on ? p.current * p.current * rho * m.wire_length() / m.area() : 0.0;
  const double t_ss = p.ambient + power / m.conductance();
  const double t_th = t_ss + (s.temperature - t_ss) * std::exp(-dt / m.time_constant());
  auto tension = [&](double x) {
    double k = m.stiffness_austenite() + x * (m.stiffness_martensite() - m.stiffness_austenite());
    const double ks = m.series_stiffness();
    if (ks > 0) k = k * ks / (k + ks);  // coupling spring in series
    return std::max(0.0, k * (stretch - x * m.recoverable_stretch()));
  };
  auto teff = [&](double x, double c) {
    return t_th + p.latent_heat / p.specific_heat * (x - s.xi) - m.Stress(tension(x)) / c;
  };
  auto major = [](double t, double lo, double hi) {
    if (t <= lo) return 1.0;
    if (t >= hi) return 0.0;
    return 0.5 * (std::cos(kPi * (t - lo) / (hi - lo)) + 1);
  };
  auto g_heat = [&](double x) { return x - s.heat_scale * major(teff(x, p.C_A), p.As, p.Af); };
  auto g_cool = [&](double x) {
    return x - 1 + s.cool_scale * (1 - major(teff(x, p.C_M), p.Mf, p.Ms));
  };
  auto bisect = [](auto g, double lo, double hi) {
    for (int i = 0; i < 200 && hi - lo > 0; ++i) {
      const double mid = 0.5 * (lo + hi);
      if (mid <= lo || mid >= hi) break;
      (g(mid) > 0 ? hi : lo) = mid;
    }
    return 0.5 * (lo + hi);
  };
  if (teff(s.xi, p.C_A) >= s.t_eff) {
    return {g_heat(s.xi) > 1e-12 ? bisect(g_heat, 0.0, s.xi) : s.xi, true};
  }
  return {g_cool(s.xi) < -1e-12 ? bisect(g_cool, s.xi, 1.0) : s.xi, false};
}

class FastPhaseSolve : public ::testing::TestWithParam<bool> {};

TEST_P(FastPhaseSolve, MatchesBisectionWithLibmCosine) {
  // Defaults (wire and coupling spring) and the old coil, latent heat on, loaded by the
  // prestretch.
  const UnitParams p = GetParam() ? UnitParams{} : Coil();
  const UnitModel m = MakeModel(p);
  UnitState s = RestState(m, p.prestretch);
  int transformed = 0;
  double worst = 0;
  for (int i = 0; i < 12000; ++i) {
    // On for 4 s, off for 2 s, on for 1 s (a minor loop), off again.
    const bool on = i < 4000 || (i >= 6000 && i < 7000);
    const RefStep ref = ReferencePhaseStep(m, s, on, p.prestretch, 1e-3);
    const double xi0 = s.xi;
    AdvanceUnit(m, s, on, p.prestretch, 1e-3);
    // Newton stops on a step below 1e-10; where the residual touches zero with zero slope
    // (T_eff reaching Mf or Af) convergence is linear and the last step bounds the error.
    ASSERT_NEAR(s.xi, ref.xi, 1e-10) << "step " << i << (ref.heating ? " heating" : " cooling");
    worst = std::max(worst, std::abs(s.xi - ref.xi));
    if (s.xi != xi0) ++transformed;
  }
  RecordProperty("worst_xi_error", std::to_string(worst));
  std::printf("worst |xi - reference| = %.3g over %d transforming steps\n", worst, transformed);
  EXPECT_GT(transformed, 1000);  // the comparison covered many transforming steps
}

INSTANTIATE_TEST_SUITE_P(DefaultAndCoil, FastPhaseSolve, ::testing::Bool());

TEST(UnitHysteresis, PolynomialSinCosMatchesLibmOverTheHalfTurn) {
  double worst = 0;
  const int n = 1 << 20;
  for (int i = 0; i <= n; ++i) {
    const double a = kPi * i / n;
    double sn, cs;
    SinCosHalfTurn(a, &sn, &cs);
    worst = std::max({worst, std::abs(sn - std::sin(a)), std::abs(cs - std::cos(a))});
  }
  EXPECT_LT(worst, 1e-15);
}

TEST(UnitForce, SpringTensionMatchesSpringFormulas) {
  UnitParams p = Coil();
  const UnitModel m = MakeModel(p);
  const double d = p.wire_diameter, D = p.coil_diameter, n = p.turns;
  const double k_a = p.G_A * std::pow(d, 4) / (8 * D * D * D * n);
  const double k_m = p.G_M * std::pow(d, 4) / (8 * D * D * D * n);
  const double stretch_l = kPi * n * D * D * std::sqrt(3.0) * p.eps_L / d;
  EXPECT_NEAR(m.Tension(0, 2e-3), k_a * 2e-3, 1e-12);
  EXPECT_NEAR(m.Tension(1, 1.5 * stretch_l), k_m * 0.5 * stretch_l, 1e-12);
  EXPECT_EQ(m.Tension(1, 0.5 * stretch_l), 0.0);  // slack: tension only
  EXPECT_EQ(m.Tension(0, -1e-3), 0.0);
  const double k_half = 0.5 * (k_a + k_m);
  EXPECT_NEAR(m.Tension(0.5, 4e-3), k_half * (4e-3 - 0.5 * stretch_l), 1e-12);
}

TEST(UnitForce, WireTensionMatchesMixtureLaw) {
  UnitParams p;
  p.law = ForceLaw::kWire;
  p.series_spring = 0;
  p.wire_length = 0.2;
  const UnitModel m = MakeModel(p);
  const double a = kPi * p.wire_diameter * p.wire_diameter / 4;
  // sigma = E(xi) (eps - eps_L xi), E(xi) = E_A + xi (E_M - E_A), F = A max(0, sigma).
  for (double xi : {0.0, 0.3, 1.0}) {
    for (double eps : {0.0, 0.01, 0.03, 0.05}) {
      const double e = p.E_A + xi * (p.E_M - p.E_A);
      const double f = a * std::max(0.0, e * (eps - p.eps_L * xi));
      EXPECT_NEAR(m.Tension(xi, eps * p.wire_length), f, 1e-9 * (1 + f));
    }
  }
}

TEST(UnitForce, CouplingSpringActsInSeriesWithTheWire) {
  // Wire (E A / L) and coupling spring k_s in series: 1 / k = 1 / k_w(xi) + 1 / k_s,
  // F = k (stretch - xi eps_L L).
  UnitParams p;
  p.series_spring = 114;
  const UnitModel m = MakeModel(p);
  const double a = kPi * p.wire_diameter * p.wire_diameter / 4;
  for (double xi : {0.0, 0.4, 1.0}) {
    const double kw = (p.E_A + xi * (p.E_M - p.E_A)) * a / p.wire_length;
    const double k = 1 / (1 / kw + 1 / 114.0);
    const double stretch = 6e-3;
    const double f = k * (stretch - xi * p.eps_L * p.wire_length);
    EXPECT_NEAR(m.Tension(xi, stretch), f, 1e-12) << "xi=" << xi;
    // Slope against a central difference.
    const double h = 1e-6;
    const double fd =
        (m.Tension(xi + (xi < 1 ? h : -h), stretch) - m.Tension(xi, stretch)) / (xi < 1 ? h : -h);
    EXPECT_NEAR(m.TensionSlope(xi, stretch), fd, 1e-4 * std::abs(fd));
  }
}

// A unit of `series` segments of `parallel` wires (plain wires, no coupling spring).
UnitModel Segments(int series, int parallel, double series_spring) {
  UnitParams p;
  p.series = series;
  p.parallel = parallel;
  p.series_spring = series_spring;
  return MakeModel(p);
}

TEST(UnitGeometry, ParallelWiresMultiplyForceAndShareStress) {
  for (double ks : {0.0, 114.0}) {
    const UnitModel one = Segments(1, 1, ks), two = Segments(1, 2, ks), three = Segments(1, 3, ks);
    for (double xi : {0.0, 0.5, 1.0}) {
      const double f1 = one.Tension(xi, 5e-3);
      EXPECT_NEAR(two.Tension(xi, 5e-3), 2 * f1, 1e-12);
      EXPECT_NEAR(three.Tension(xi, 5e-3), 3 * f1, 1e-12);
      // Each wire carries 1 / parallel of the unit's tension: the same wire stress.
      EXPECT_NEAR(two.WireStress(2 * f1), one.WireStress(f1), 1e-6);
    }
    // True tensile stress of the plain wire law: F / (parallel A).
    const double a = kPi * 0.1e-3 * 0.1e-3 / 4;
    EXPECT_NEAR(two.WireStress(1.0), 1.0 / (2 * a), 1e-3);
  }
}

TEST(UnitGeometry, SeriesSegmentsMultiplyStrokeAtTheSameForce) {
  for (double ks : {0.0, 114.0}) {
    const UnitModel one = Segments(1, 1, ks), two = Segments(2, 1, ks);
    // A tendon extension e splits into e / 2 per segment: the same force at twice the stretch.
    for (double xi : {0.0, 0.3, 1.0}) {
      for (double e : {1e-3, 4e-3, 7e-3}) {
        EXPECT_NEAR(two.Tension(xi, 2 * e), one.Tension(xi, e), 1e-12);
      }
    }
    // Free stroke (stretch at which the martensite unit goes slack): eps_L L per segment.
    EXPECT_NEAR(two.recoverable_stretch(), 2 * 0.04 * 0.1, 1e-15);
    EXPECT_EQ(two.Tension(1, 2 * 0.04 * 0.1 - 1e-6), 0.0);
    EXPECT_GT(two.Tension(1, 2 * 0.04 * 0.1 + 1e-6), 0.0);
  }
}

TEST(UnitModelCreate, RejectsSeriesParallelBelowOneAndNegativeSpring) {
  UnitParams p;
  p.series = 0;
  auto m = UnitModel::Create(p);
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().find("series=0"), std::string::npos) << m.error();
  p = UnitParams{};
  p.parallel = -2;
  EXPECT_FALSE(UnitModel::Create(p).ok());
  p = UnitParams{};
  p.series_spring = -1;
  EXPECT_FALSE(UnitModel::Create(p).ok());
}

// Dynalloy Flexinol wire table (diameter mm, current for a 1 s contraction A, LT cooling time
// s), written out here independently of plugin/unit_model.cc.
struct Row {
  double d_mm, current, cooling;
};
constexpr Row kDatasheet[] = {
    {0.050, 0.085, 0.4}, {0.100, 0.200, 1.1}, {0.150, 0.410, 2.0}, {0.250, 1.050, 5.4}};

TEST(UnitLimits, ForWireReproducesTheDatasheetRows) {
  for (const Row& r : kDatasheet) {
    const UnitLimits lim = UnitLimits::ForWire(r.d_mm * 1e-3);
    EXPECT_NEAR(lim.max_current, r.current, 1e-9) << r.d_mm;
    EXPECT_NEAR(lim.cooling_time, r.cooling, 1e-9) << r.d_mm;
    EXPECT_EQ(lim.max_wire_stress, 172e6);
  }
  // Between 0.1 and 0.127 mm (200 and 320 mA) the current lies between the rows.
  const UnitLimits mid = UnitLimits::ForWire(0.11e-3);
  EXPECT_GT(mid.max_current, 0.2);
  EXPECT_LT(mid.max_current, 0.32);
}

// Steady isometric state of one default unit held on at its prestretch (20 s = 20 tau).
UnitState SettledOn(const UnitModel& m) {
  UnitState s = RestState(m, m.params().prestretch);
  for (int i = 0; i < 20000; ++i) AdvanceUnit(m, s, true, m.params().prestretch, 1e-3);
  return s;
}

TEST(DefaultUnit, SteadyOnTemperatureIsAboveAfAndWithinTheLimit) {
  const UnitParams p;
  const UnitModel m = MakeModel(p);
  const UnitState s = SettledOn(m);
  // Energy balance of a fully transformed wire: I^2 rho_A / A = h pi d (T - T_amb).
  const double d = p.wire_diameter, a = kPi * d * d / 4;
  const double h = m.heat_transfer_coefficient();
  const double t_ss = p.ambient + p.current * p.current * p.resistivity_A / a / (h * kPi * d);
  EXPECT_NEAR(s.temperature, t_ss, 1e-6);
  EXPECT_EQ(s.xi, 0.0);  // fully contracted: the force is set by geometry, not by temperature
  EXPECT_GT(s.temperature, p.Af + 20);
  EXPECT_LE(s.temperature, UnitLimits{}.max_temperature);
  // Natural convection around a 0.1 mm wire: SMA-NOTES give about 140 W/(m^2 K).
  EXPECT_GT(h, 100);
  EXPECT_LT(h, 160);
}

TEST(DefaultUnit, WireStressAtTheSettledForceIsWithinTheRatedPull) {
  const UnitParams p;
  const UnitModel m = MakeModel(p);
  const UnitState s = SettledOn(m);
  const double f = m.Tension(s.xi, p.prestretch);
  const double sigma = f / (kPi * p.wire_diameter * p.wire_diameter / 4);
  EXPECT_NEAR(m.WireStress(f), sigma, 1e-6 * sigma);
  EXPECT_LE(sigma, 172e6);  // Dynalloy: 172 MPa for long cycle life
  // Worst case at this length: fully austenite wire (xi = 0) pulls k_A * prestretch.
  EXPECT_LE(m.WireStress(m.Tension(0, p.prestretch)), 172e6);
  // And the wire reset stress in martensite is below Dynalloy's 70 MPa deformation guidance.
  EXPECT_LE(m.WireStress(m.Tension(1, p.prestretch)), 70e6);
}

TEST(DefaultUnit, CurrentAndPowerAreWithinTheDatasheetValueForTheDiameter) {
  const UnitParams p;
  ASSERT_DOUBLE_EQ(p.wire_diameter, 0.1e-3);
  EXPECT_LE(p.current, kDatasheet[1].current);  // 200 mA for 0.1 mm
  // Resistance per metre against the datasheet's 126 ohm/m (austenite resistivity).
  const double r_per_m = p.resistivity_A / (kPi * 0.1e-3 * 0.1e-3 / 4);
  EXPECT_NEAR(r_per_m, 126, 5);
  const UnitModel m = MakeModel(p);
  EXPECT_NEAR(m.HeatingPower(true, 0), p.current * p.current * r_per_m * p.wire_length, 1e-12);
}

TEST(DefaultUnit, CoolingTimeMatchesTheDatasheet) {
  // Dynalloy's cooling time: still air, from just contracted until relaxed but for the last
  // 0.5 % of the stroke. Here: an unloaded default wire heated at its current until fully
  // austenite, then switched off; time until xi >= 0.995. Band: within a factor 2 of the
  // datasheet's 1.1 s. The model comes out slow (about 2.0 s, docs/sma-units.md): unloaded it
  // must cool to Mf = 42 C (a loaded wire relaxes about 7 K earlier at 70 MPa) and it releases
  // the latent heat (29 K worth) on the way; the table is "approximate" besides.
  UnitParams p;
  p.prestretch = 0;
  const UnitModel m = MakeModel(p);
  UnitState s = RestState(m, 0);
  int i = 0;
  while (s.xi > 0 && i < 100000) {
    AdvanceUnit(m, s, true, 0, 1e-4);
    ++i;
  }
  ASSERT_EQ(s.xi, 0.0);
  double t = 0;
  while (s.xi < 0.995 && t < 100) {
    AdvanceUnit(m, s, false, 0, 1e-4);
    t += 1e-4;
  }
  std::printf("cooling time %.2f s (datasheet 1.1 s), tau %.2f s\n", t, m.time_constant());
  EXPECT_GT(t, 1.1 / 2);
  EXPECT_LT(t, 1.1 * 2);
}

TEST(UnitModelCreate, RejectsInconsistentTransformationTemperatures) {
  UnitParams p = Coil();
  p.Ms = 40;  // below Mf = 42
  auto m = UnitModel::Create(p);
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().find("Mf"), std::string::npos);
  p = Coil();
  p.Af = 60;
  EXPECT_FALSE(UnitModel::Create(p).ok());
  p = Coil();
  p.coil_diameter = 0.05e-3;  // smaller than the wire
  EXPECT_FALSE(UnitModel::Create(p).ok());
}

}  // namespace file_unit_model_test
}  // namespace recruit::sma
