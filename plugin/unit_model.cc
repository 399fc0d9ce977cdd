#include "plugin/unit_model.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "common/cpu_features.h"
#include "common/short_text.h"
#include "plugin/unit_batch.h"

namespace recruit::sma {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kStefanBoltzmann = 5.670374419e-8;  // W/(m^2 K^4)
constexpr double kGravity = 9.81;                    // m/s^2

// Root of a monotone increasing g on [lo, hi] by Newton's method from x (g and slope given),
// safeguarded by the bracket: a step that leaves it bisects instead. The step-to-step change of
// xi is small, so 2-3 iterations usually suffice. gd(x, &g, &dg) evaluates g and its slope.
template <class GD>
double SolveNewton(const GD& gd, double lo, double hi, double x, double g, double dg) {
  for (int it = 0; it < 60; ++it) {
    if (g > 0) {
      hi = x;
    } else {
      lo = x;
    }
    double next = dg > 0 ? x - g / dg : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    const double step = next - x;
    x = next;
    // Newton converges quadratically: after a step below 1e-10 the remaining error is far
    // smaller (and at most the step where g has a kink), so x is accepted unevaluated.
    if (std::abs(step) < 1e-10 || hi - lo < 1e-15) break;
    gd(x, &g, &dg);
    if (std::abs(g) < 1e-13) break;
  }
  return x;
}

// Dynalloy Flexinol wire table: diameter (mm), current for a 1 s contraction (mA), still-air
// cooling time of LT wire (s).
struct DatasheetRow {
  double d_mm, current_ma, cooling_s;
};
constexpr DatasheetRow kFlexinol[] = {{0.025, 45, 0.18},  {0.038, 55, 0.24},   {0.050, 85, 0.4},
                                      {0.076, 150, 0.8},  {0.100, 200, 1.1},   {0.127, 320, 1.6},
                                      {0.150, 410, 2.0},  {0.200, 660, 3.2},   {0.250, 1050, 5.4},
                                      {0.310, 1500, 8.1}, {0.380, 2250, 10.5}, {0.510, 4000, 16.8}};

}  // namespace

UnitLimits UnitLimits::ForWire(double d) {
  UnitLimits lim;
  const double dmm = d * 1e3;
  constexpr int n = sizeof kFlexinol / sizeof kFlexinol[0];
  int i = 0;
  while (i < n - 2 && dmm > kFlexinol[i + 1].d_mm) ++i;
  const DatasheetRow& a = kFlexinol[i];
  const DatasheetRow& b = kFlexinol[i + 1];
  const double x = std::clamp(dmm, kFlexinol[0].d_mm, kFlexinol[n - 1].d_mm);
  const double w = std::log(x / a.d_mm) / std::log(b.d_mm / a.d_mm);
  auto interp = [w](double ya, double yb) { return ya * std::pow(yb / ya, w); };
  lim.max_current = 1e-3 * interp(a.current_ma, b.current_ma);
  lim.cooling_time = interp(a.cooling_s, b.cooling_s);
  return lim;
}

double UnitModel::NaturalConvectionH(double d, double ambient, double dT, double emissivity) {
  dT = std::max(dT, 1.0);
  const double t_amb = ambient + 273.15;
  const double t_film = t_amb + 0.5 * dT;
  // Air at 1 atm, linear between 300 K and 350 K (Incropera & DeWitt, Table A.4).
  const double s = (t_film - 300.0) / 50.0;
  const double k = 0.0263 + s * (0.0300 - 0.0263);         // W/(m K)
  const double nu = 15.89e-6 + s * (20.92e-6 - 15.89e-6);  // m^2/s
  const double alpha = 22.5e-6 + s * (29.9e-6 - 22.5e-6);  // m^2/s
  const double ra = kGravity * (1.0 / t_film) * dT * d * d * d / (nu * alpha);
  // Morgan (1975), horizontal cylinder: Nu = C Ra^n by range of Ra.
  double c = 0.675, n = 0.058;
  if (ra >= 1e7) {
    c = 0.125, n = 0.333;
  } else if (ra >= 1e4) {
    c = 0.480, n = 0.250;
  } else if (ra >= 1e2) {
    c = 0.850, n = 0.188;
  } else if (ra >= 1e-2) {
    c = 1.02, n = 0.148;
  }
  const double h_conv = c * std::pow(ra, n) * k / d;
  const double t_s = t_amb + dT;
  const double h_rad = emissivity * kStefanBoltzmann * (t_s * t_s + t_amb * t_amb) * (t_s + t_amb);
  return h_conv + h_rad;
}

Result<UnitModel> UnitModel::Create(const UnitParams& p) {
  if (!(p.Mf < p.Ms)) return Error{"Mf=" + GText(p.Mf) + " must be below Ms=" + GText(p.Ms)};
  if (!(p.As < p.Af)) return Error{"As=" + GText(p.As) + " must be below Af=" + GText(p.Af)};
  if (p.law == ForceLaw::kSpring && !(p.coil_diameter > p.wire_diameter)) {
    return Error{"coil_diameter=" + GText(p.coil_diameter) +
                 " must exceed wire_diameter=" + GText(p.wire_diameter)};
  }
  if (p.series < 1 || p.parallel < 1) {
    return Error{"series=" + GText(p.series) + " and parallel=" + GText(p.parallel) +
                 " must be whole numbers >= 1"};
  }
  if (!(p.series_spring >= 0)) {
    return Error{"series_spring=" + GText(p.series_spring) + " must be >= 0 (0 = rigid)"};
  }
  UnitModel m;
  m.p_ = p;
  const double d = p.wire_diameter;
  m.area_ = kPi * d * d / 4;
  m.h_ = p.h > 0 ? p.h
                 : NaturalConvectionH(d, p.ambient, 0.5 * (p.As + p.Af) - p.ambient, p.emissivity);
  m.length_ = p.law == ForceLaw::kSpring ? kPi * p.coil_diameter * p.turns : p.wire_length;
  m.heat_capacity_ = p.density * p.specific_heat * m.area_ * m.length_;
  m.conductance_ = m.h_ * kPi * d * m.length_;
  m.tau_ = m.heat_capacity_ / m.conductance_;
  m.latent_rise_ = p.latent_heat / p.specific_heat;
  m.heat_rate_ = kPi / (p.Af - p.As);
  m.cool_rate_ = kPi / (p.Ms - p.Mf);
  if (p.law == ForceLaw::kWire) {
    m.k_A_ = p.E_A * m.area_ / p.wire_length;
    m.k_M_ = p.E_M * m.area_ / p.wire_length;
    m.stretch_L_ = p.eps_L * p.wire_length;
    m.stress_per_newton_ = 1.0 / m.area_;
  } else {
    const double D = p.coil_diameter;
    const double geom = d * d * d * d / (8 * D * D * D * p.turns);
    m.k_A_ = p.G_A * geom;
    m.k_M_ = p.G_M * geom;
    m.stretch_L_ = kPi * p.turns * D * D * std::sqrt(3.0) * p.eps_L / d;
    const double index = D / d;
    const double wahl = (4 * index - 1) / (4 * index - 4) + 0.615 / index;
    m.stress_per_newton_ = std::sqrt(3.0) * 8 * D * wahl / (kPi * d * d * d);
  }
  // One segment of `parallel` wires takes stretch / series: the unit's stiffness is
  // parallel / series times one wire's, its stroke series times, and each wire carries
  // 1 / parallel of the unit's tension.
  const double scale = static_cast<double>(p.parallel) / p.series;
  m.k_A_ *= scale;
  m.k_M_ *= scale;
  m.k_s_ = p.series_spring * scale;
  m.stretch_L_ *= p.series;
  m.stress_per_newton_ /= p.parallel;
  m.heat_shift_per_newton_ = m.stress_per_newton_ / p.C_A;
  m.cool_shift_per_newton_ = m.stress_per_newton_ / p.C_M;
  const double joule = p.current * p.current * m.length_ / m.area_;  // W per (ohm m)
  m.on_power_A_ = joule * p.resistivity_A;
  m.on_power_dM_ = joule * (p.resistivity_M - p.resistivity_A);
  m.on_rise_A_ = m.on_power_A_ / m.conductance_;
  m.on_rise_dM_ = m.on_power_dM_ / m.conductance_;
  m.batch_ = {m.k_A_,
              m.k_M_,
              m.k_s_,
              m.stretch_L_,
              m.latent_rise_,
              m.heat_shift_per_newton_,
              m.cool_shift_per_newton_,
              p.As,
              p.Af,
              p.Ms,
              p.Mf,
              m.heat_rate_,
              m.cool_rate_,
              p.ambient,
              m.on_rise_A_,
              m.on_rise_dM_};
  return m;
}

double UnitModel::MajorHeating(double t_eff) const {
  if (t_eff <= p_.As) return 1;
  if (t_eff >= p_.Af) return 0;
  double sn, cs;
  SinCosHalfTurn(heat_rate_ * (t_eff - p_.As), &sn, &cs);
  return 0.5 * (cs + 1);
}

double UnitModel::MajorCooling(double t_eff) const {
  if (t_eff <= p_.Mf) return 1;
  if (t_eff >= p_.Ms) return 0;
  double sn, cs;
  SinCosHalfTurn(cool_rate_ * (t_eff - p_.Mf), &sn, &cs);
  return 0.5 * (cs + 1);
}

double UnitModel::MajorHeating(double t_eff, double* slope) const {
  if (t_eff <= p_.As || t_eff >= p_.Af) {
    *slope = 0;
    return t_eff <= p_.As ? 1 : 0;
  }
  const double w = heat_rate_;
  double sn, cs;
  SinCosHalfTurn(w * (t_eff - p_.As), &sn, &cs);
  *slope = -0.5 * w * sn;
  return 0.5 * (cs + 1);
}

double UnitModel::MajorCooling(double t_eff, double* slope) const {
  if (t_eff <= p_.Mf || t_eff >= p_.Ms) {
    *slope = 0;
    return t_eff <= p_.Mf ? 1 : 0;
  }
  const double w = cool_rate_;
  double sn, cs;
  SinCosHalfTurn(w * (t_eff - p_.Mf), &sn, &cs);
  *slope = -0.5 * w * sn;
  return 0.5 * (cs + 1);
}

double UnitModel::TensionSlope(double xi, double stretch) const {
  double slope;
  Tension(xi, stretch, &slope);
  return slope;
}

double UnitModel::Stiffness(double xi, double* dk) const {
  const double kw = k_A_ + xi * (k_M_ - k_A_);
  if (k_s_ <= 0) {
    *dk = k_M_ - k_A_;
    return kw;
  }
  // Springs in series: k = kw ks / (kw + ks); dk/dxi = ks^2 kw' / (kw + ks)^2.
  const double inv = 1.0 / (kw + k_s_);
  *dk = k_s_ * k_s_ * (k_M_ - k_A_) * inv * inv;
  return kw * k_s_ * inv;
}

double UnitModel::Tension(double xi, double stretch, double* slope) const {
  double dk;
  const double k = Stiffness(xi, &dk);
  const double e = stretch - xi * stretch_L_;
  if (k * e <= 0) {
    *slope = 0;
    return 0;
  }
  *slope = dk * e - k * stretch_L_;
  return k * e;
}

double UnitModel::Tension(double xi, double stretch) const {
  double dk;
  const double k = Stiffness(xi, &dk);
  return std::max(0.0, k * (stretch - xi * stretch_L_));
}

double UnitModel::HeatingPower(bool on, double xi) const {
  if (!on) return 0;
  return on_power_A_ + xi * on_power_dM_;  // I^2 rho(xi) l / A, rho linear in xi
}

double UnitModel::SteadyTemperature(bool on, double xi) const {
  return on ? p_.ambient + (on_rise_A_ + xi * on_rise_dM_) : p_.ambient;
}

double UnitModel::DecayFactor(double dt) const { return std::exp(-dt / tau_); }

double UnitModel::ThermalStep(double t, bool on, double xi, double dt) const {
  const double t_ss = SteadyTemperature(on, xi);
  return t_ss + (t - t_ss) * DecayFactor(dt);
}

UnitState RestState(const UnitModel& m, double stretch) {
  UnitState s;
  s.temperature = m.params().ambient;
  s.xi = 1;
  s.t_eff = s.temperature - m.Stress(m.Tension(1, stretch)) / m.params().C_M;
  return s;
}

namespace {

void SolvePhase(const UnitModel& m, UnitState& s, double t_thermal, double stretch) {
  const double xi0 = s.xi;
  const double latent = m.latent_rise();  // K per unit of xi
  // Temperature after the step if xi ends at x: latent heat is absorbed by M -> A (x < xi0).
  auto temp = [&](double x) { return t_thermal + latent * (x - xi0); };
  const double per_newton_h = m.heat_shift_per_newton();  // K of T_eff shift per N of tension
  const double per_newton_c = m.cool_shift_per_newton();
  auto teff_h = [&](double x) { return temp(x) - per_newton_h * m.Tension(x, stretch); };
  auto teff_c = [&](double x) { return temp(x) - per_newton_c * m.Tension(x, stretch); };
  // Both residuals have slope >= 1 in x: T_eff rises as x falls (stress rises, latent heat is
  // released as x rises), and M+, M- are non-increasing.
  // With slopes, for Newton: dT_eff/dx = L/c - (dsigma/dF) (dF/dx) / C >= 0.
  auto gd_h = [&](double x, double* g, double* dg) {
    double slope, dfdx;
    const double te = temp(x) - per_newton_h * m.Tension(x, stretch, &dfdx);
    *g = x - s.heat_scale * m.MajorHeating(te, &slope);
    *dg = 1 - s.heat_scale * slope * (latent - per_newton_h * dfdx);
  };
  auto gd_c = [&](double x, double* g, double* dg) {
    double slope, dfdx;
    const double te = temp(x) - per_newton_c * m.Tension(x, stretch, &dfdx);
    *g = x - 1 + s.cool_scale * (1 - m.MajorCooling(te, &slope));
    *dg = 1 - s.cool_scale * slope * (latent - per_newton_c * dfdx);
  };

  double xi = xi0;
  double te;
  // Tension and its slope at xi0, shared by the branch test and the first residual of either
  // branch (the values gd_h(xi0) and gd_c(xi0) would compute; temp(xi0) = t_thermal).
  double dfdx0;
  const double f0 = m.Tension(xi0, stretch, &dfdx0);
  const double te_h0 = t_thermal - per_newton_h * f0;
  if (te_h0 >= s.t_eff) {
    // Heating (or steady): M -> A only, xi can only fall.
    te = te_h0;
    double slope0;
    const double g0 = xi0 - s.heat_scale * m.MajorHeating(te_h0, &slope0);
    const double dg0 = 1 - s.heat_scale * slope0 * (latent - per_newton_h * dfdx0);
    if (g0 > 1e-12) {
      xi = SolveNewton(gd_h, 0.0, xi0, xi0, g0, dg0);
      te = teff_h(xi);
      // Transformed: a later cooling branch starts from here.
      const double mm = m.MajorCooling(te);
      s.cool_scale = mm < 1 ? std::clamp((1 - xi) / (1 - mm), 0.0, 1.0) : 1.0;
    }
  } else {
    // Cooling: A -> M only, xi can only rise.
    te = t_thermal - per_newton_c * f0;
    double slope0;
    const double g0 = xi0 - 1 + s.cool_scale * (1 - m.MajorCooling(te, &slope0));
    const double dg0 = 1 - s.cool_scale * slope0 * (latent - per_newton_c * dfdx0);
    if (g0 < -1e-12) {
      xi = SolveNewton(gd_c, xi0, 1.0, xi0, g0, dg0);
      te = teff_c(xi);
      const double mp = m.MajorHeating(te);
      s.heat_scale = mp > 0 ? std::clamp(xi / mp, 0.0, 1.0) : 1.0;
    }
  }
  // Canonical ends of the loop, so that settled units in the same state compare equal.
  if (xi >= 1 - 1e-12) {
    xi = 1;
    s.heat_scale = 1;
    s.cool_scale = 0;
  } else if (xi <= 1e-12) {
    xi = 0;
    s.heat_scale = 0;
    s.cool_scale = 1;
  }
  s.xi = xi;
  s.temperature = temp(xi);
  s.t_eff = te;
}

}  // namespace

void AdvanceUnit(const UnitModel& m, UnitState& s, bool on, double stretch, double dt) {
  AdvanceUnitWithDecay(m, s, on, stretch, m.DecayFactor(dt));
}

void ImposeTemperature(const UnitModel& m, UnitState& s, double t, double stretch) {
  SolvePhase(m, s, t, stretch);
}

void AdvanceUnitWithDecay(const UnitModel& m, UnitState& s, bool on, double stretch, double decay) {
  const double t_ss = m.SteadyTemperature(on, s.xi);
  SolvePhase(m, s, t_ss + (s.temperature - t_ss) * decay, stretch);
}

namespace {

// The CPU's features, read once when the library loads: a function-local static would test its
// guard at every dispatch of a kernel (twice per step). Before initialisation (another library's
// static constructors) both read false, which selects the build's own kernels: same results.
struct CpuFeatures {
  bool avx2 = false, avx512 = false;
  CpuFeatures() {
#ifdef RECRUIT_SMA_AVX2_CLONE
    avx2 = CpuRunsAvx2();
#ifdef RECRUIT_SMA_AVX512_CLONE
    avx512 = avx2 && CpuRunsAvx512FDq();
#endif
#endif
  }
};
const CpuFeatures cpu;

bool UseAvx2(UnitModel::Isa isa) { return isa != UnitModel::Isa::kBase && cpu.avx2; }

// The 8-lane update: asked for, or kAuto on a CPU that has it.
bool UseAvx512(UnitModel::Isa isa) {
  return (isa == UnitModel::Isa::kAuto || isa == UnitModel::Isa::kAvx512) && cpu.avx512;
}

}  // namespace

bool UnitModel::HasAvx2() { return cpu.avx2; }
bool UnitModel::HasAvx512() { return cpu.avx512; }

int UnitModel::Lanes(Isa isa) {
  if (UseAvx512(isa)) return 8;
  if (UseAvx2(isa)) return 4;
#ifdef __AVX__
  return 4;
#else
  return 2;
#endif
}

inline void UnitModel::Update(const Cohorts& c, int n, double stretch, double decay, Isa isa,
                              BatchObserve* obs) const {
  // The scalar update of cohort j (the batched kernels' reference).
  auto scalar = [&](int j) {
    UnitState s{c.temperature[j], c.xi[j], c.t_eff[j], c.heat_scale[j], c.cool_scale[j]};
    AdvanceUnitWithDecay(*this, s, c.on[j] != 0, stretch, decay);
    c.temperature[j] = s.temperature, c.xi[j] = s.xi, c.t_eff[j] = s.t_eff;
    c.heat_scale[j] = s.heat_scale, c.cool_scale[j] = s.cool_scale;
    return s;
  };
  if (n == 1 && isa == Isa::kAuto) {  // one cohort (units switched together): the scalar update
    const UnitState s = scalar(0);
    if (obs != nullptr) {
      // SumTelemetry's few-cohort path for this one cohort, from the values just computed: each
      // sum is +0 + count v (its partial sums start at +0: never -0; the other three add +0),
      // the peak max(0, tension).
      const double cnt = obs->count[0], t = Tension(s.xi, obs->stretch);
      const double terms[4] = {cnt * c.on[0], cnt * s.temperature, cnt * s.xi, cnt * t};
      for (int f = 0; f < 4; ++f) obs->out[f] = 0.0 + terms[f];
      obs->out[4] = std::max(0.0, t);
      obs->out[5] = s.temperature;
      obs->done = true;
    }
    return;
  }
  const BatchParams& bp = batch_;
  const BatchCohorts bc{c.on, c.temperature, c.xi, c.t_eff, c.heat_scale, c.cool_scale};
#ifdef RECRUIT_SMA_AVX512_CLONE
  // Up to four cohorts (an arm's bundle in a closed loop) fill AVX2's one block, whose update
  // costs 0.81-0.83x the AVX-512 one's half-empty block; from five on they cost about the same,
  // 0.96x for eight (plugin_bench BM_KernelAvx512OverAvx2: thread CPU time, transforming cohorts).
  const bool few = n <= 4 && isa == Isa::kAuto && UseAvx2(isa);
  // The AVX-512 update gives no telemetry (its 8-lane fold was never run on a machine with
  // AVX-512): the run loop then sums as it did before (ReadTelemetry).
  if (UseAvx512(isa) && !few)
    return batch_avx512::AdvanceCohorts(bp, bc, n, stretch, decay, nullptr);
#endif
  // One cohort more than a SIMD block (5 with AVX2): that one by the scalar update, about half
  // what a second block of one real lane costs, then the block, whose telemetry (obs) takes in
  // the scalar cohort's new values. Only under kAuto (the tests run each kernel on its own).
  const bool avx2 = UseAvx2(isa);
  if (isa == Isa::kAuto && n == (avx2 ? 4 : Lanes(Isa::kBase)) + 1) {
    scalar(n - 1);
#ifdef RECRUIT_SMA_AVX2_CLONE
    if (avx2) return batch_avx2::AdvanceBlockBeforeUpdatedTail(bp, bc, n, stretch, decay, obs);
#endif
    return batch_base::AdvanceBlockBeforeUpdatedTail(bp, bc, n, stretch, decay, obs);
  }
#ifdef RECRUIT_SMA_AVX2_CLONE
  if (avx2) return batch_avx2::AdvanceCohorts(bp, bc, n, stretch, decay, obs);
#endif
  batch_base::AdvanceCohorts(bp, bc, n, stretch, decay, obs);
}

void UnitModel::AdvanceCohorts(const Cohorts& c, int n, double stretch, double decay, Isa isa,
                               BatchObserve* obs) const {
  if (obs != nullptr) obs->done = false;
  Update(c, n, stretch, decay, isa, obs);
}

double UnitModel::SumTension(const double* count, const double* xi, int n, double stretch,
                             Isa isa) const {
  if (n < 4 && isa == Isa::kAuto) {  // the kernels' four partial sums, without the kernel
    double a[4] = {0, 0, 0, 0};
    for (int j = 0; j < n; ++j) a[j] += count[j] * Tension(xi[j], stretch);
    return (a[0] + a[1]) + (a[2] + a[3]);
  }
  const BatchParams& bp = batch_;
#ifdef RECRUIT_SMA_AVX2_CLONE
  if (UseAvx2(isa)) return batch_avx2::SumTension(bp, count, xi, n, stretch);
#endif
  return batch_base::SumTension(bp, count, xi, n, stretch);
}

void UnitModel::WeightedSums(const double* count, const double* const* v, int nf, int n,
                             double* out) {
  if (n < 4) {  // the kernels' four partial sums, without the kernel
    for (int f = 0; f < nf; ++f) {
      double a[4] = {0, 0, 0, 0};
      for (int j = 0; j < n; ++j) a[j] += count[j] * v[f][j];
      out[f] = (a[0] + a[1]) + (a[2] + a[3]);
    }
    return;
  }
#ifdef RECRUIT_SMA_AVX2_CLONE
  if (UseAvx2(Isa::kAuto)) return batch_avx2::WeightedSums(count, v, nf, n, out);
#endif
  batch_base::WeightedSums(count, v, nf, n, out);
}

void UnitModel::SumTelemetry(const double* count, const double* const* v, int n, double stretch,
                             bool peak, double* out, Isa isa) const {
  if (n < 4 && isa == Isa::kAuto) {  // WeightedSums' and SumTension's paths for few cohorts
    double a[4][4] = {}, top = 0;
    for (int j = 0; j < n; ++j) {
      const double t = Tension(v[2][j], stretch);
      for (int f = 0; f < 3; ++f) a[f][j] += count[j] * v[f][j];
      a[3][j] += count[j] * t;
      top = std::max(top, t);
    }
    for (int f = 0; f < 4; ++f) out[f] = (a[f][0] + a[f][1]) + (a[f][2] + a[f][3]);
    if (peak) out[4] = top;
    return;
  }
  const BatchParams& bp = batch_;
#ifdef RECRUIT_SMA_AVX2_CLONE
  if (UseAvx2(isa)) return batch_avx2::SumTelemetry(bp, count, v, n, stretch, peak, out);
#endif
  batch_base::SumTelemetry(bp, count, v, n, stretch, peak, out);
}

bool UnitModel::MergeOrder(const double* on, const double* temp, int n, int* order, double* t,
                           int* idx, Isa isa) {
#ifdef RECRUIT_SMA_AVX512_CLONE
  if (UseAvx512(isa)) return batch_avx512::MergeOrder(on, temp, n, order, t, idx);
#endif
#ifdef RECRUIT_SMA_AVX2_CLONE
  if (UseAvx2(isa)) return batch_avx2::MergeOrder(on, temp, n, order, t, idx);
#endif
  return batch_base::MergeOrder(on, temp, n, order, t, idx);
}

void UnitModel::Relabel(double* idx, int n, const int* remap) {
#ifdef RECRUIT_SMA_AVX2_CLONE
  if (UseAvx2(Isa::kAuto)) return batch_avx2::Relabel(idx, n, remap);
#endif
  batch_base::Relabel(idx, n, remap);
}

}  // namespace recruit::sma
