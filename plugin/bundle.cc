#include "plugin/bundle.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <vector>

#include "common/rng.h"

namespace recruit::sma {
namespace {

constexpr double kMagic = 5318008.25;  // marks an initialised block (mj_resetData zeroes it)

Rng LoadRng(const double* words) {
  Rng::State st;
  std::memcpy(st.data(), words, sizeof st);
  return Rng::FromState(st);
}

void StoreRng(const Rng& rng, double* words) {
  std::memcpy(words, rng.state().data(), sizeof(Rng::State));
}

}  // namespace

SmaBundle::SmaBundle(BundleConfig c, UnitModel u, double dt)
    : config_(std::move(c)),
      unit_(std::move(u)),
      limits_(UnitLimits::ForWire(config_.unit.wire_diameter)),
      dt_(dt),
      decay_(unit_.DecayFactor(dt)) {
  if (config_.update_period > 0) {
    // The pending time reaches about a whole number of steps >= update_period.
    period_ = dt_ * std::max(1.0, std::round(config_.update_period / dt_));
    decay_period_ = unit_.DecayFactor(period_);
  }
}

Result<SmaBundle> SmaBundle::Create(const BundleConfig& config, double dt) {
  auto unit = UnitModel::Create(config.unit);
  if (!unit.ok()) return Error{"actuator '" + config.actuator + "': " + unit.error()};
  if (!(dt > 0)) return Error{"actuator '" + config.actuator + "': timestep must be > 0"};
  return SmaBundle(config, std::move(unit.value()), dt);
}

void SmaBundle::Reset(double* s, std::uint64_t seed, double stretch) const {
  std::fill(s, s + state_size(), 0.0);
  s[kMagicSlot] = kMagic;
  StoreRng(Rng(seed), s + kRngSlot);
  s[kCohortCountSlot] = 1;
  const UnitState rest = RestState(unit_, stretch);
  double* c = Cohort(s, 0);
  c[kCount] = config_.units;
  c[kOn] = 0;
  c[kTemp] = rest.temperature;
  c[kXi] = rest.xi;
  c[kTeff] = rest.t_eff;
  c[kHeatScale] = rest.heat_scale;
  c[kCoolScale] = rest.cool_scale;
  // Unit index block is already 0: every unit in cohort 0.
}

bool SmaBundle::Initialized(const double* s) { return s[kMagicSlot] == kMagic; }

Status SmaBundle::Broadcast(double* s, double p_on, double p_off, double stretch) const {
  if (!(p_on >= 0 && p_on <= 1) || !(p_off >= 0 && p_off <= 1)) {
    return Error{"actuator '" + config_.actuator + "': broadcast probabilities must be in [0, 1]"};
  }
  Flush(s, stretch);  // time not yet integrated ran with the old on/off states
  Rng rng = LoadRng(s + kRngSlot);
  const int k0 = NumCohorts(s);
  double* idx = UnitIndex(s);
  // Pass 1: every unit draws, in unit order.
  std::vector<int> flips(k0, 0);
  std::vector<char> flip(config_.units, 0);
  for (int i = 0; i < config_.units; ++i) {
    const int from = static_cast<int>(idx[i]);
    const double u = rng.Uniform();
    if (u < (Cohort(s, from)[kOn] != 0 ? p_off : p_on)) {
      flip[i] = 1;
      ++flips[from];
    }
  }
  StoreRng(rng, s + kRngSlot);
  // Pass 2: a cohort whose units all switch flips in place; one that splits gets a new cohort
  // for its switching units. Non-empty cohorts never exceed N, so the N slots suffice.
  std::vector<int> target(k0, -1);
  int k = k0;
  for (int j = 0; j < k0; ++j) {
    if (flips[j] == 0) continue;
    double* c = Cohort(s, j);
    if (flips[j] == static_cast<int>(c[kCount])) {
      c[kOn] = c[kOn] != 0 ? 0 : 1;
      target[j] = j;
      continue;
    }
    double* n = Cohort(s, k);
    std::copy(c, c + kCohortStride, n);
    n[kCount] = flips[j];
    n[kOn] = c[kOn] != 0 ? 0 : 1;
    c[kCount] -= flips[j];
    target[j] = k++;
  }
  for (int i = 0; i < config_.units; ++i) {
    if (flip[i]) idx[i] = target[static_cast<int>(idx[i])];
  }
  s[kCohortCountSlot] = k;
  return Status::Ok();
}

void SmaBundle::Advance(double* s, double stretch, double dt) const {
  if (config_.update_period <= 0) {
    Integrate(s, stretch, dt);
    return;
  }
  s[kPendingSlot] += dt;
  if (s[kPendingSlot] >= config_.update_period - 0.5 * dt) Flush(s, stretch);
}

void SmaBundle::Flush(double* s, double stretch) const {
  const double t = s[kPendingSlot];
  s[kPendingSlot] = 0;
  if (t > 0) Integrate(s, stretch, t);
}

void SmaBundle::Integrate(double* s, double stretch, double dt) const {
  double decay;
  if (dt == dt_) {
    decay = decay_;
  } else if (std::abs(dt - period_) < 1e-9 * period_) {
    decay = decay_period_;
  } else {
    decay = unit_.DecayFactor(dt);
  }
  const int k = NumCohorts(s);
  for (int j = 0; j < k; ++j) {
    double* c = Cohort(s, j);
    UnitState st{c[kTemp], c[kXi], c[kTeff], c[kHeatScale], c[kCoolScale]};
    AdvanceUnitWithDecay(unit_, st, c[kOn] != 0, stretch, decay);
    c[kTemp] = st.temperature;
    c[kXi] = st.xi;
    c[kTeff] = st.t_eff;
    c[kHeatScale] = st.heat_scale;
    c[kCoolScale] = st.cool_scale;
  }
  s[kCounterSlot] += 1;
  if (k > 1 && std::fmod(s[kCounterSlot], kMergeEvery) == 0) Merge(s);
}

void SmaBundle::Merge(double* s) const {
  const int k = NumCohorts(s);
  std::vector<int> order(k);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    const double* ca = Cohort(s, a);
    const double* cb = Cohort(s, b);
    if (ca[kOn] != cb[kOn]) return ca[kOn] < cb[kOn];
    return ca[kTemp] < cb[kTemp];
  });
  bool merged = false;
  std::vector<int> forward(k, -1);  // representative that absorbed each merged cohort
  int rep = order[0];
  for (int j = 1; j < k; ++j) {
    double* r = Cohort(s, rep);
    double* c = Cohort(s, order[j]);
    const bool same = r[kOn] == c[kOn] &&
                      std::abs(r[kTemp] - c[kTemp]) <= config_.merge_temperature &&
                      std::abs(r[kXi] - c[kXi]) <= config_.merge_xi &&
                      std::abs(r[kHeatScale] - c[kHeatScale]) <= config_.merge_xi &&
                      std::abs(r[kCoolScale] - c[kCoolScale]) <= config_.merge_xi;
    if (!same) {
      rep = order[j];
      continue;
    }
    // Count-weighted mean keeps the bundle's mean temperature and fraction.
    const double n = r[kCount] + c[kCount];
    for (int f : {kTemp, kXi, kTeff, kHeatScale, kCoolScale})
      r[f] = (r[f] * r[kCount] + c[f] * c[kCount]) / n;
    r[kCount] = n;
    c[kCount] = 0;
    forward[order[j]] = rep;
    merged = true;
  }
  if (merged) Compact(s, forward);
}

void SmaBundle::Compact(double* s, const std::vector<int>& forward) const {
  const int k = NumCohorts(s);
  // New index for each surviving cohort; a merged cohort forwards its units to its
  // representative.
  std::vector<int> remap(k, -1);
  int n = 0;
  for (int j = 0; j < k; ++j) {
    if (Cohort(s, j)[kCount] > 0) remap[j] = n++;
  }
  for (int j = 0; j < k; ++j) {
    if (remap[j] < 0 && j < static_cast<int>(forward.size()) && forward[j] >= 0) {
      remap[j] = remap[forward[j]];
    }
  }
  double* idx = UnitIndex(s);
  for (int i = 0; i < config_.units; ++i) idx[i] = remap[static_cast<int>(idx[i])];
  for (int j = 0; j < k; ++j) {
    if (Cohort(s, j)[kCount] > 0 && remap[j] != j) {
      std::copy(Cohort(s, j), Cohort(s, j) + kCohortStride, Cohort(s, remap[j]));
    }
  }
  s[kCohortCountSlot] = n;
}

double SmaBundle::Tension(const double* s, double stretch) const {
  const int k = NumCohorts(s);
  double f = 0;
  for (int j = 0; j < k; ++j) {
    const double* c = Cohort(s, j);
    f += c[kCount] * unit_.Tension(c[kXi], stretch);
  }
  return f;
}

int SmaBundle::OnCount(const double* s) const {
  const int k = NumCohorts(s);
  double n = 0;
  for (int j = 0; j < k; ++j) {
    const double* c = Cohort(s, j);
    if (c[kOn] != 0) n += c[kCount];
  }
  return static_cast<int>(n);
}

double SmaBundle::MeanTemperature(const double* s) const {
  const int k = NumCohorts(s);
  if (k == 0) return config_.unit.ambient;
  double t = 0;
  for (int j = 0; j < k; ++j) t += Cohort(s, j)[kCount] * Cohort(s, j)[kTemp];
  return t / config_.units;
}

double SmaBundle::MeanXi(const double* s) const {
  const int k = NumCohorts(s);
  if (k == 0) return 1;
  double x = 0;
  for (int j = 0; j < k; ++j) x += Cohort(s, j)[kCount] * Cohort(s, j)[kXi];
  return x / config_.units;
}

double SmaBundle::Heat(const double* s) const {
  const double amb = config_.unit.ambient;
  const double span = unit_.on_temperature() - amb;
  if (!(span > 0)) return 0;  // current=0: on units do not heat
  return std::clamp((MeanTemperature(s) - amb) / span, 0.0, 1.0);
}

double SmaBundle::MaxTemperature(const double* s) const {
  const int k = NumCohorts(s);
  double t = config_.unit.ambient;
  for (int j = 0; j < k; ++j) t = j == 0 ? Cohort(s, j)[kTemp] : std::max(t, Cohort(s, j)[kTemp]);
  return t;
}

double SmaBundle::MaxWireStress(const double* s, double stretch) const {
  const int k = NumCohorts(s);
  double f = 0;
  for (int j = 0; j < k; ++j) f = std::max(f, unit_.Tension(Cohort(s, j)[kXi], stretch));
  return unit_.WireStress(f);
}

int SmaBundle::UnitCohort(const double* s, int i) const {
  return static_cast<int>(UnitIndex(s)[i]);
}
bool SmaBundle::UnitOn(const double* s, int i) const {
  return Cohort(s, UnitCohort(s, i))[kOn] != 0;
}
double SmaBundle::UnitTemperature(const double* s, int i) const {
  return Cohort(s, UnitCohort(s, i))[kTemp];
}
double SmaBundle::UnitXi(const double* s, int i) const { return Cohort(s, UnitCohort(s, i))[kXi]; }

double SmaBundle::SettledOnTension(double stretch) const {
  // The fixed point of the exact thermal step and the implicit phase solve does not depend on
  // the step, so long steps (tau / 10 for 40 tau) reach it cheaply.
  const double dt = unit_.time_constant() / 10;
  UnitState st = RestState(unit_, stretch);
  const double decay = unit_.DecayFactor(dt);
  for (int i = 0; i < 10 * 40; ++i) AdvanceUnitWithDecay(unit_, st, true, stretch, decay);
  return unit_.Tension(st.xi, stretch);
}

}  // namespace recruit::sma
