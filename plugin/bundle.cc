#include "plugin/bundle.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <vector>

#include "common/rng.h"

namespace recruit::sma {
namespace {

constexpr double kMagic = 5318008.25;  // marks an initialised block (mj_resetData zeroes it)

// A cohort's merge sort key: on/off state, then temperature.
struct MergeKey {
  double on, temp;
  int index;
};

// The merge's scratch for more cohorts than fit on the stack.
struct BigMergeScratch {
  std::vector<MergeKey> order;
  std::vector<int> sorted, forward, remap;
  std::vector<double> t;
};

// The stream's four 64-bit words as eight 32-bit halves (low, high), each an integer-valued
// double: exact and finite, so the block survives NaN checks, text and float64 round trips.
Rng LoadRng(const double* halves) {
  Rng::State st;
  for (int w = 0; w < 4; ++w) {
    st[w] = static_cast<std::uint64_t>(halves[2 * w]) |
            static_cast<std::uint64_t>(halves[2 * w + 1]) << 32;
  }
  return Rng::FromState(st);
}

void StoreRng(const Rng& rng, double* halves) {
  for (int w = 0; w < 4; ++w) {
    const std::uint64_t x = rng.state()[w];
    halves[2 * w] = static_cast<double>(x & 0xFFFFFFFFu);
    halves[2 * w + 1] = static_cast<double>(x >> 32);
  }
}

// Binomial(n, p): by inversion from one uniform when n p is small (failures are rare, so the
// loop rarely goes past k = 0), else one Bernoulli draw per unit (where (1 - p)^n would
// underflow).
int Binomial(Rng& rng, int n, double p) {
  if (n <= 0 || !(p > 0)) return 0;
  if (p >= 1) return n;
  if (n * p > 10) {
    int k = 0;
    for (int i = 0; i < n; ++i) k += rng.Uniform() < p ? 1 : 0;
    return k;
  }
  const double u = rng.Uniform();
  double pmf = std::pow(1 - p, n), cdf = pmf;
  int k = 0;
  while (u >= cdf && k < n) {
    pmf *= (n - k) / (k + 1.0) * (p / (1 - p));
    ++k;
    cdf += pmf;
  }
  return k;
}

// Picks `want` of the units i < n with eligible(i) true (there are `pool`), uniformly, in unit
// order (selection sampling, Knuth's Algorithm S): one draw per eligible unit until done.
template <class Eligible>
void PickUnits(Rng& rng, int n, int pool, int want, Eligible eligible, std::vector<int>* out) {
  for (int i = 0; i < n && want > 0; ++i) {
    if (!eligible(i)) continue;
    if (rng.Uniform() * pool < want) {
      out->push_back(i);
      --want;
    }
    --pool;
  }
}

constexpr std::uint64_t kFailureStream = 0xFA11ED;  // sub-stream index of the failure draws
constexpr std::uint64_t kCensusStream = 0xCE4505;   // sub-stream of the census's shunt noise

}  // namespace

SmaBundle::SmaBundle(BundleConfig c, UnitModel u, double dt)
    : config_(std::move(c)),
      unit_(std::move(u)),
      limits_(UnitLimits::ForWire(config_.unit.wire_diameter)),
      dt_(dt),
      decay_(unit_.DecayFactor(dt)) {
  failures_ = config_.failure.given;
  census_ = config_.census.given;
  fatigue_ = failures_ && config_.failure.fatigue_loss > 0;
  if (config_.update_period > 0) {
    // The pending time reaches about a whole number of steps >= update_period.
    period_ = dt_ * std::max(1.0, std::round(config_.update_period / dt_));
    decay_period_ = unit_.DecayFactor(period_);
  }
}

Result<SmaBundle> SmaBundle::Create(const BundleConfig& config, double dt) {
  auto unit = UnitModel::Create(config.unit);
  if (!unit.ok()) return Error{"actuator '" + config.actuator + "': " + unit.error(), unit.code()};
  if (!(dt > 0)) return Error{"actuator '" + config.actuator + "': timestep must be > 0"};
  return SmaBundle(config, std::move(unit.value()), dt);
}

void SmaBundle::Reset(double* s, std::uint64_t seed, double stretch) const {
  std::fill(s, s + state_size(), 0.0);
  s[kMagicSlot] = kMagic;
  StoreRng(Rng(seed), s + kRngSlot);
  s[kCohortCountSlot] = 1;
  const UnitState rest = RestState(unit_, stretch);
  Field(s, kCount)[0] = config_.units;
  Field(s, kOn)[0] = 0;
  Field(s, kTemp)[0] = rest.temperature;
  Field(s, kXi)[0] = rest.xi;
  Field(s, kTeff)[0] = rest.t_eff;
  Field(s, kHeatScale)[0] = rest.heat_scale;
  Field(s, kCoolScale)[0] = rest.cool_scale;
  // Unit index block is already 0: every unit in cohort 0.
  if (failures_) StoreRng(Rng(Rng::DeriveSeed(seed, kFailureStream)), Fail(s) + kFailRngSlot);
  // Modes and damage are 0: every unit working and fresh.
  if (census_) {
    double* c = CensusBlock(s);
    StoreRng(Rng(Rng::DeriveSeed(seed, kCensusStream)), c + kCensusRngSlot);
  }
}

bool SmaBundle::Initialized(const double* s) { return s[kMagicSlot] == kMagic; }

void SmaBundle::CopyCohort(double* s, int from, int to) const {
  for (int f = 0; f < kFields; ++f) Field(s, f)[to] = Field(s, f)[from];
  if (failures_) {
    Mode(s)[to] = Mode(s)[from];
    Damage(s)[to] = Damage(s)[from];
  }
}

double SmaBundle::ForceScale(double damage) const {
  const FailureConfig& f = config_.failure;
  return 1 - f.fatigue_loss * -std::expm1(-damage / f.fatigue_cycles);
}

Status SmaBundle::Broadcast(double* s, double p_on, double p_off, double stretch) const {
  if (!(p_on >= 0 && p_on <= 1) || !(p_off >= 0 && p_off <= 1)) {
    return Error{"actuator '" + config_.actuator + "': broadcast probabilities must be in [0, 1]"};
  }
  DropAllKept(s);
  Flush(s, stretch);  // time not yet integrated ran with the old on/off states
  Rng rng = LoadRng(s + kRngSlot);
  const int k0 = NumCohorts(s);
  double* idx = UnitIndex(s);
  double* count = Field(s, kCount);
  double* on = Field(s, kOn);
  // Pass 1: every unit draws, in unit order.
  std::vector<int> flips(k0, 0);
  std::vector<char> flip(config_.units, 0);
  for (int i = 0; i < config_.units; ++i) {
    const int from = static_cast<int>(idx[i]);
    const double u = rng.Uniform();
    // A failed unit draws like the others (the working units' draws do not depend on which
    // units failed) but does not switch.
    if (failures_ && Mode(s)[from] != kModeWorking) continue;
    if (u < (on[from] != 0 ? p_off : p_on)) {
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
    // Fatigue: a heating cycle ends (on -> off); it adds the fraction transformed times the
    // stress ratio to the power m (docs/failures.md).
    double damage = 0;
    if (fatigue_ && on[j] != 0) {
      const FailureConfig& fc = config_.failure;
      const double xi = Field(s, kXi)[j];
      const double stress = unit_.WireStress(ForceScale(Damage(s)[j]) * unit_.Tension(xi, stretch));
      damage = (1 - xi) * std::pow(stress / fc.fatigue_stress, fc.fatigue_exponent);
    }
    if (flips[j] == static_cast<int>(count[j])) {
      on[j] = on[j] != 0 ? 0 : 1;
      if (fatigue_) Damage(s)[j] += damage;
      target[j] = j;
      continue;
    }
    CopyCohort(s, j, k);
    count[k] = flips[j];
    on[k] = on[j] != 0 ? 0 : 1;
    if (fatigue_) Damage(s)[k] += damage;
    count[j] -= flips[j];
    target[j] = k++;
  }
  for (int i = 0; i < config_.units; ++i) {
    if (flip[i]) idx[i] = target[static_cast<int>(idx[i])];
  }
  s[kCohortCountSlot] = k;
  if (failures_) CycleFailures(s, flip, stretch);
  return Status::Ok();
}

Status SmaBundle::StartCensus(double* s, double stretch) const {
  if (!census_) {
    return Error{"actuator '" + config_.actuator +
                 "': no census: give a census key (census_on, census_off, census_noise)"};
  }
  if (CensusRunning(s)) return Error{"actuator '" + config_.actuator + "': a census is running"};
  DropAllKept(s);
  Flush(s, stretch);  // pending time ran with the latched heaters
  double* c = CensusBlock(s);
  c[kCensusOnLeftSlot] = config_.census.on;
  c[kCensusOffLeftSlot] = config_.census.off;
  return Status::Ok();
}

bool SmaBundle::CensusRunning(const double* s) const {
  if (!census_) return false;
  const double* c = CensusBlock(s);
  return c[kCensusOnLeftSlot] > 0 || c[kCensusOffLeftSlot] > 0;
}

SmaBundle::CensusReading SmaBundle::LastCensus(const double* s) const {
  CensusReading r;
  if (!census_) return r;
  const double* c = CensusBlock(s);
  r.number = static_cast<int>(c[kCensusNumberSlot]);
  r.on_current = c[kCensusOnReadingSlot];
  r.off_current = c[kCensusOffReadingSlot];
  return r;
}

double SmaBundle::CensusReadingNow(double* s, bool on) const {
  const FailureCounts f = Failures(s);
  const int conducting = on ? f.working + f.stuck : f.stuck;
  double* c = CensusBlock(s);
  Rng rng = LoadRng(c + kCensusRngSlot);
  const double noise = config_.census.noise * rng.Gaussian();
  StoreRng(rng, c + kCensusRngSlot);
  return conducting * UnitCurrent() + noise;
}

void SmaBundle::AdvanceCensus(double* s, double stretch, double dt) const {
  double* c = CensusBlock(s);
  std::vector<double> heater;
  double left = dt;
  for (const bool on : {true, false}) {
    double& phase = c[on ? kCensusOnLeftSlot : kCensusOffLeftSlot];
    if (!(phase > 0) || !(left > 0)) continue;
    const int k = NumCohorts(s);
    heater.assign(k, 0.0);
    for (int j = 0; j < k; ++j) {
      const int mode = failures_ ? static_cast<int>(Mode(s)[j]) : kModeWorking;
      heater[j] = on ? (mode != kModeOpen) : (mode == kModeStuck);
    }
    // A phase that ends within 1e-9 s of the step's end ends with it (sums of dt round).
    const bool ends = phase <= left + 1e-9;
    const double piece = ends ? std::min(phase, left) : left;
    Integrate(s, stretch, piece, heater.data());
    phase = ends ? 0 : phase - left;
    left = left - piece < 1e-9 ? 0 : left - piece;
    if (ends) {
      c[on ? kCensusOnReadingSlot : kCensusOffReadingSlot] = CensusReadingNow(s, on);
      if (!on) c[kCensusNumberSlot] += 1;
    }
  }
  if (!(left > 0)) return;
  if (config_.update_period <= 0) {
    Integrate(s, stretch, left);
  } else {
    s[kPendingSlot] += left;
  }
}

void SmaBundle::Advance(double* s, double stretch, double dt, double observe_stretch) const {
  DropAllKept(s);
  const bool observe = s[kObserveSlot] == 1 && !std::isnan(observe_stretch);
  // The update's own pass gives the telemetry when it is the last change of the step (failures
  // may change the cohorts after it).
  BatchObserve obs;  // out[] written by the update
  obs.count = Field(s, kCount);
  obs.stretch = observe_stretch;
  obs.done = false;
  BatchObserve* fused = observe && !failures_ ? &obs : nullptr;
  if (census_ && CensusRunning(s)) {
    AdvanceCensus(s, stretch, dt);
  } else if (config_.update_period <= 0) {
    Integrate(s, stretch, dt, nullptr, fused);
  } else {
    s[kPendingSlot] += dt;
    if (s[kPendingSlot] >= config_.update_period - 0.5 * dt) Flush(s, stretch);
  }
  if (failures_) StepFailures(s, stretch, dt);
  // Otherwise ReadTelemetry sums afresh when it is read.
  if (obs.done) KeepTelemetry(s, observe_stretch, obs);
}

void SmaBundle::FailUnits(double* s, const std::vector<int>& units, int mode) const {
  if (units.empty()) return;
  const int k0 = NumCohorts(s);
  double* idx = UnitIndex(s);
  double* count = Field(s, kCount);
  double* on = Field(s, kOn);
  std::vector<int> moving(k0, 0), target(k0, -1);
  for (int i : units) ++moving[static_cast<int>(idx[i])];
  int k = k0;
  for (int j = 0; j < k0; ++j) {
    if (moving[j] == 0) continue;
    int t = j;
    if (moving[j] != static_cast<int>(count[j])) {
      t = k++;
      CopyCohort(s, j, t);
      count[t] = moving[j];
      count[j] -= moving[j];
    }
    on[t] = mode == kModeStuck ? 1 : 0;  // open: never heats; stuck: heated for good
    Mode(s)[t] = mode;
    target[j] = t;
  }
  for (int i : units) idx[i] = target[static_cast<int>(idx[i])];
  s[kCohortCountSlot] = k;
}

void SmaBundle::CycleFailures(double* s, const std::vector<char>& flip, double stretch) const {
  const FailureConfig& fc = config_.failure;
  if (!(fc.open_per_cycle > 0 || fc.stuck_per_cycle > 0)) return;
  double* f = Fail(s);
  Rng rng = LoadRng(f + kFailRngSlot);
  const double* idx = UnitIndex(s);
  std::vector<int> open, stuck;
  for (int i = 0; i < config_.units; ++i) {
    const int j = static_cast<int>(idx[i]);
    // A cycle starts when a working unit switches on.
    if (!flip[i] || Field(s, kOn)[j] == 0 || Mode(s)[j] != kModeWorking) continue;
    const double u = rng.Uniform();
    if (u < fc.open_per_cycle) {
      open.push_back(i);
    } else if (u < fc.open_per_cycle + fc.stuck_per_cycle) {
      stuck.push_back(i);
    }
  }
  StoreRng(rng, f + kFailRngSlot);
  FailUnits(s, open, kModeOpen);
  FailUnits(s, stuck, kModeStuck);
}

void SmaBundle::StepFailures(double* s, double stretch, double dt) const {
  const FailureConfig& fc = config_.failure;
  double* f = Fail(s);
  f[kFailTimeSlot] += dt;
  const int n_events = static_cast<int>(fc.schedule.size());
  const bool due =
      f[kFailNextSlot] < n_events &&
      fc.schedule[static_cast<int>(f[kFailNextSlot])].time <= f[kFailTimeSlot] + 0.5 * dt;
  const double rate = (fc.open_rate + fc.stuck_rate) / 3600.0;  // per second heated
  if (!due && !(rate > 0)) return;
  Rng rng = LoadRng(f + kFailRngSlot);
  const double* idx = UnitIndex(s);
  const double* count = Field(s, kCount);
  const double* on = Field(s, kOn);
  std::vector<int> open, stuck, picked;
  if (rate > 0) {
    const double p = -std::expm1(-rate * dt);
    const int k = NumCohorts(s);
    for (int j = 0; j < k; ++j) {
      if (Mode(s)[j] != kModeWorking || on[j] == 0) continue;
      const int n = static_cast<int>(count[j]);
      const int failing = Binomial(rng, n, p);
      if (failing == 0) continue;
      picked.clear();
      PickUnits(
          rng, config_.units, n, failing, [&](int i) { return idx[i] == j; }, &picked);
      for (int i : picked) {
        (rng.Uniform() * (fc.open_rate + fc.stuck_rate) < fc.open_rate ? open : stuck).push_back(i);
      }
    }
  }
  const bool any = !open.empty() || !stuck.empty() || due;
  if (any && s[kPendingSlot] > 0) Flush(s, stretch);  // the old states ran until now
  FailUnits(s, open, kModeOpen);
  FailUnits(s, stuck, kModeStuck);
  while (f[kFailNextSlot] < n_events) {
    const FailureConfig::Event& e = fc.schedule[static_cast<int>(f[kFailNextSlot])];
    if (!(e.time <= f[kFailTimeSlot] + 0.5 * dt)) break;
    f[kFailNextSlot] += 1;
    const int working = Failures(s).working;
    picked.clear();
    const double* ix = UnitIndex(s);
    PickUnits(
        rng, config_.units, working, std::min(e.count, working),
        [&](int i) { return Mode(s)[static_cast<int>(ix[i])] == kModeWorking; }, &picked);
    FailUnits(s, picked, e.stuck ? kModeStuck : kModeOpen);
  }
  StoreRng(rng, f + kFailRngSlot);
}

void SmaBundle::Flush(double* s, double stretch) const {
  const double t = s[kPendingSlot];
  s[kPendingSlot] = 0;
  if (t > 0) Integrate(s, stretch, t);
}

void SmaBundle::Integrate(double* s, double stretch, double dt, const double* heater,
                          BatchObserve* obs) const {
  double decay;
  if (dt == dt_) {
    decay = decay_;
  } else if (std::abs(dt - period_) < 1e-9 * period_) {
    decay = decay_period_;
  } else {
    decay = unit_.DecayFactor(dt);
  }
  const int k = NumCohorts(s);
  const UnitModel::Cohorts c{heater ? heater : Field(s, kOn),
                             Field(s, kTemp),
                             Field(s, kXi),
                             Field(s, kTeff),
                             Field(s, kHeatScale),
                             Field(s, kCoolScale)};
  unit_.AdvanceCohorts(c, k, stretch, decay, UnitModel::Isa::kAuto, obs);
  s[kCounterSlot] += 1;
  // The counter is a whole number: integer modulo instead of a libm fmod call.
  if (k > 1 && static_cast<long long>(s[kCounterSlot]) % kMergeEvery == 0) {
    Merge(s);
    if (config_.unit_model == UnitModelKind::kBinned && NumCohorts(s) > config_.bins) Bin(s);
    // A merge leaves fewer cohorts (merged ones are compacted away): the update's telemetry was
    // of the cohorts before it.
    if (obs != nullptr && NumCohorts(s) != k) obs->done = false;
  }
}

void SmaBundle::Bin(double* s) const {
  struct Scratch {
    std::vector<int> seq, pairs, forward, remap;
    std::vector<double> cost;
    std::vector<char> used;
  };
  static thread_local Scratch w;  // bundles may step in parallel on their own mjData
  const int k = NumCohorts(s);
  double* count = Field(s, kCount);
  double* f[kFields];
  for (int i = 0; i < kFields; ++i) f[i] = Field(s, i);
  const double *on = f[kOn], *temp = f[kTemp];
  w.seq.resize(k);
  std::iota(w.seq.begin(), w.seq.end(), 0);
  std::sort(w.seq.begin(), w.seq.end(), [&](int a, int b) {
    if (on[a] != on[b]) return on[a] < on[b];
    if (temp[a] != temp[b]) return temp[a] < temp[b];
    return a < b;
  });
  w.forward.assign(k, -1);
  // A pair's distance: its largest difference in units of the merge tolerances (the defaults'
  // where one is 0), so the pass widens Merge's box evenly, the nearest pairs first.
  const double per_kelvin = 1 / (config_.merge_temperature > 0 ? config_.merge_temperature : 0.5);
  const double per_xi = 1 / (config_.merge_xi > 0 ? config_.merge_xi : 0.01);
  auto distance = [&](int a, int b) {
    double d = std::max({per_kelvin * std::abs(temp[a] - temp[b]),
                         per_xi * std::abs(f[kXi][a] - f[kXi][b]),
                         per_xi * std::abs(f[kHeatScale][a] - f[kHeatScale][b]),
                         per_xi * std::abs(f[kCoolScale][a] - f[kCoolScale][b])});
    if (fatigue_) {
      d = std::max(d, per_xi * std::abs(ForceScale(Damage(s)[a]) - ForceScale(Damage(s)[b])));
    }
    return d;
  };
  auto compatible = [&](int a, int b) {
    return on[a] == on[b] && (!failures_ || Mode(s)[a] == Mode(s)[b]);
  };
  int alive = k;
  // Rounds: the cheapest neighbours first, each cohort in at most one merge per round.
  while (alive > config_.bins) {
    const int m = static_cast<int>(w.seq.size());
    w.pairs.clear();
    w.cost.resize(m);
    for (int i = 0; i + 1 < m; ++i) {
      if (!compatible(w.seq[i], w.seq[i + 1])) continue;
      w.cost[i] = distance(w.seq[i], w.seq[i + 1]);
      w.pairs.push_back(i);
    }
    if (w.pairs.empty()) break;  // one cohort per on/off state and failure mode
    std::sort(w.pairs.begin(), w.pairs.end(),
              [&](int a, int b) { return w.cost[a] != w.cost[b] ? w.cost[a] < w.cost[b] : a < b; });
    w.used.assign(m, 0);
    for (int i : w.pairs) {
      if (alive <= config_.bins) break;
      if (w.used[i] || w.used[i + 1]) continue;
      w.used[i] = w.used[i + 1] = 1;
      const int r = w.seq[i], c = w.seq[i + 1];
      // Count-weighted mean, as Merge: the bundle's mean temperature and fraction are kept.
      const double n = count[r] + count[c];
      for (int fi : {kTemp, kXi, kTeff, kHeatScale, kCoolScale}) {
        f[fi][r] = (f[fi][r] * count[r] + f[fi][c] * count[c]) / n;
      }
      if (fatigue_) Damage(s)[r] = (Damage(s)[r] * count[r] + Damage(s)[c] * count[c]) / n;
      count[r] = n;
      count[c] = 0;
      w.forward[c] = r;
      --alive;
    }
    w.seq.erase(std::remove_if(w.seq.begin(), w.seq.end(), [&](int j) { return count[j] == 0; }),
                w.seq.end());
  }
  // A cohort merged into one merged later forwards to where its chain ends.
  for (int j = 0; j < k; ++j) {
    int t = w.forward[j];
    while (t >= 0 && w.forward[t] >= 0) t = w.forward[t];
    w.forward[j] = t;
  }
  w.remap.resize(k);
  Compact(s, w.forward.data(), w.remap.data());
}

void SmaBundle::Merge(double* s) const {
  const int k = NumCohorts(s);
  // Scratch on the stack up to 64 cohorts, else reused per thread (bundles may step in
  // parallel on their own mjData).
  constexpr int kSmall = 64;
  MergeKey small_order[kSmall];
  int small_sorted[3 * kSmall + 16], small_forward[kSmall], small_remap[kSmall];
  double small_t[2 * kSmall + 16];
  int* sorted = small_sorted;
  int* forward = small_forward;
  int* remap = small_remap;
  double* t_scratch = small_t;
  MergeKey* order = small_order;
  if (k > kSmall) {
    static thread_local BigMergeScratch big;
    big.order.resize(k);
    big.sorted.resize(3 * k + 16);
    big.forward.resize(k);
    big.remap.resize(k);
    big.t.resize(2 * k + 16);
    order = big.order.data();
    sorted = big.sorted.data();
    forward = big.forward.data();
    remap = big.remap.data();
    t_scratch = big.t.data();
  }
  // Cohort indices sorted by (on, T). Without ties the order is unique, and MergeOrder finds it
  // without the sort's unpredictable branches (k^2 / 2 comparisons in SIMD lanes: faster than
  // the sort up to about 300 random keys, 3.5 against 4.1 us at 256, 7.9 against 7.2 us at 384 on
  // AVX-512); with ties or more cohorts, std::sort as before: keys held by value, whose moves
  // depend only on the comparisons, so the order of ties is that of sorting the indices.
  constexpr int kSimdMerge = 320;
  const double *on = Field(s, kOn), *temp = Field(s, kTemp);
  if (k > kSimdMerge || !UnitModel::MergeOrder(on, temp, k, sorted, t_scratch, sorted + k)) {
    for (int j = 0; j < k; ++j) order[j] = {on[j], temp[j], j};
    std::sort(order, order + k, [](const MergeKey& a, const MergeKey& b) {
      if (a.on != b.on) return a.on < b.on;
      return a.temp < b.temp;
    });
    for (int j = 0; j < k; ++j) sorted[j] = order[j].index;
  }
  bool merged = false;
  std::fill(forward, forward + k, -1);  // representative that absorbed each merged cohort
  double* count = Field(s, kCount);
  double* f[kFields];
  for (int i = 0; i < kFields; ++i) f[i] = Field(s, i);
  int rep = sorted[0];
  for (int j = 1; j < k; ++j) {
    const int r = rep, c = sorted[j];
    const bool same =
        on[r] == on[c] && std::abs(temp[r] - temp[c]) <= config_.merge_temperature &&
        std::abs(f[kXi][r] - f[kXi][c]) <= config_.merge_xi &&
        std::abs(f[kHeatScale][r] - f[kHeatScale][c]) <= config_.merge_xi &&
        std::abs(f[kCoolScale][r] - f[kCoolScale][c]) <= config_.merge_xi &&
        (!failures_ ||
         (Mode(s)[r] == Mode(s)[c] &&
          std::abs(ForceScale(Damage(s)[r]) - ForceScale(Damage(s)[c])) <= config_.merge_xi));
    if (!same) {
      rep = c;
      continue;
    }
    // Count-weighted mean keeps the bundle's mean temperature and fraction.
    const double n = count[r] + count[c];
    for (int i : {kTemp, kXi, kTeff, kHeatScale, kCoolScale}) {
      f[i][r] = (f[i][r] * count[r] + f[i][c] * count[c]) / n;
    }
    if (fatigue_) Damage(s)[r] = (Damage(s)[r] * count[r] + Damage(s)[c] * count[c]) / n;
    count[r] = n;
    count[c] = 0;
    forward[c] = rep;
    merged = true;
  }
  if (merged) Compact(s, forward, remap);
}

void SmaBundle::Compact(double* s, const int* forward, int* remap) const {
  const int k = NumCohorts(s);
  // New index for each surviving cohort; a merged cohort forwards its units to its
  // representative.
  const double* count = Field(s, kCount);
  std::fill(remap, remap + k, -1);
  int n = 0;
  for (int j = 0; j < k; ++j) {
    if (count[j] > 0) remap[j] = n++;
  }
  for (int j = 0; j < k; ++j) {
    if (remap[j] < 0 && forward[j] >= 0) remap[j] = remap[forward[j]];
  }
  double* idx = UnitIndex(s);
  UnitModel::Relabel(idx, config_.units, remap);
  // remap[j] <= j for survivors: copying in increasing j never overwrites one not yet moved.
  for (int j = 0; j < k; ++j) {
    if (count[j] > 0 && remap[j] != j) CopyCohort(s, j, remap[j]);
  }
  s[kCohortCountSlot] = n;
}

double SmaBundle::Tension(const double* s, double stretch) const {
  const double* w = fatigue_ ? TensionWeights(s) : Field(s, kCount);
  return unit_.SumTension(w, Field(s, kXi), NumCohorts(s), stretch);
}

const double* SmaBundle::TensionWeights(const double* s) const {
  static thread_local std::vector<double> w;
  const int k = NumCohorts(s);
  w.resize(k);
  for (int j = 0; j < k; ++j) w[j] = Field(s, kCount)[j] * ForceScale(Damage(s)[j]);
  return w.data();
}

SmaBundle::FailureCounts SmaBundle::Failures(const double* s) const {
  FailureCounts c;
  if (!failures_) {
    c.working = config_.units;
    return c;
  }
  for (int j = 0; j < NumCohorts(s); ++j) {
    const int n = static_cast<int>(Field(s, kCount)[j]);
    const double mode = Mode(s)[j];
    (mode == kModeOpen ? c.open : mode == kModeStuck ? c.stuck : c.working) += n;
  }
  return c;
}

int SmaBundle::UnitFailure(const double* s, int i) const {
  return failures_ ? static_cast<int>(Mode(s)[UnitCohort(s, i)]) : kModeWorking;
}

double SmaBundle::UnitForceScale(const double* s, int i) const {
  return fatigue_ ? ForceScale(Damage(s)[UnitCohort(s, i)]) : 1.0;
}

double SmaBundle::CountWeightedSum(const double* s, int f) const {
  const double* v[1] = {Field(s, f)};
  double sum;
  UnitModel::WeightedSums(Field(s, kCount), v, 1, NumCohorts(s), &sum);
  return sum;
}

SmaBundle::Summary SmaBundle::Summarize(const double* s, double stretch) const {
  // One pass: the sums of OnCount, MeanTemperature, MeanXi and Tension together.
  const int k = NumCohorts(s);
  const double* v[3] = {Field(s, kOn), Field(s, kTemp), Field(s, kXi)};
  double sum[4];
  unit_.SumTelemetry(Field(s, kCount), v, k, stretch, false, sum);
  if (fatigue_) sum[3] = unit_.SumTension(TensionWeights(s), Field(s, kXi), k, stretch);
  return FromSums(sum, k);
}

SmaBundle::Summary SmaBundle::FromSums(const double* sum, int k) const {
  Summary r;
  r.on_count = static_cast<int>(sum[0]);
  r.tension = sum[3];
  r.mean_temperature = k == 0 ? config_.unit.ambient : sum[1] / config_.units;
  r.mean_xi = k == 0 ? 1 : sum[2] / config_.units;
  return r;
}

SmaBundle::Telemetry SmaBundle::SumTelemetryNow(const double* s, double stretch) const {
  const int k = NumCohorts(s);
  const double* v[3] = {Field(s, kOn), Field(s, kTemp), Field(s, kXi)};
  double sum[5];
  unit_.SumTelemetry(Field(s, kCount), v, k, stretch, true, sum);
  // With fatigue the peak stays that of a fresh wire at the cohort's xi (an upper bound).
  if (fatigue_) sum[3] = unit_.SumTension(TensionWeights(s), Field(s, kXi), k, stretch);
  Telemetry r;
  static_cast<Summary&>(r) = FromSums(sum, k);
  r.max_temperature = MaxTemperature(s);
  r.max_wire_stress = unit_.WireStress(sum[4]);
  return r;
}

SmaBundle::Telemetry SmaBundle::KeptTelemetry(const double* s) {
  const double* v = s + kTelemetrySlot + 2;
  Telemetry r;
  r.on_count = static_cast<int>(v[0]);
  r.tension = v[1];
  r.mean_temperature = v[2];
  r.mean_xi = v[3];
  r.max_temperature = v[4];
  r.max_wire_stress = v[5];
  return r;
}

void SmaBundle::KeepTelemetry(double* s, double stretch, const BatchObserve& obs) const {
  // The values SumTelemetryNow gives, from the same sums and maxima.
  Telemetry r;
  static_cast<Summary&>(r) = FromSums(obs.out, NumCohorts(s));
  r.max_temperature = obs.out[5];
  r.max_wire_stress = unit_.WireStress(obs.out[4]);
  double* v = s + kTelemetrySlot;
  v[0] = 1;
  v[1] = stretch;
  v[2] = r.on_count;
  v[3] = r.tension;
  v[4] = r.mean_temperature;
  v[5] = r.mean_xi;
  v[6] = r.max_temperature;
  v[7] = r.max_wire_stress;
}

SmaBundle::Summary SmaBundle::SummarizeAndKeep(double* s, double stretch) const {
  const Summary r = Summarize(s, stretch);
  s[kKeptSlot] = 1;
  s[kKeptStretchSlot] = stretch;
  s[kKeptTensionSlot] = r.tension;
  return r;
}

double SmaBundle::TakeTension(double* s, double stretch) const {
  const bool kept = s[kKeptSlot] == 1 && s[kKeptStretchSlot] == stretch;
  const double t = kept ? s[kKeptTensionSlot] : Tension(s, stretch);
  DropKept(s);
  return t;
}

int SmaBundle::OnCount(const double* s) const { return static_cast<int>(CountWeightedSum(s, kOn)); }

double SmaBundle::MeanTemperature(const double* s) const {
  if (NumCohorts(s) == 0) return config_.unit.ambient;
  return CountWeightedSum(s, kTemp) / config_.units;
}

double SmaBundle::MeanXi(const double* s) const {
  if (NumCohorts(s) == 0) return 1;
  return CountWeightedSum(s, kXi) / config_.units;
}

double SmaBundle::Heat(const double* s) const {
  const double amb = config_.unit.ambient;
  const double span = unit_.on_temperature() - amb;
  if (!(span > 0)) return 0;  // current=0: on units do not heat
  return std::clamp((MeanTemperature(s) - amb) / span, 0.0, 1.0);
}

double SmaBundle::MaxTemperature(const double* s) const {
  const int k = NumCohorts(s);
  const double* temp = Field(s, kTemp);
  double t = k > 0 ? temp[0] : config_.unit.ambient;
  for (int j = 1; j < k; ++j) t = std::max(t, temp[j]);
  return t;
}

double SmaBundle::MaxWireStress(const double* s, double stretch) const {
  // The largest tension from SumTelemetry's SIMD pass (exactly the scalar maximum of
  // UnitModel::Tension: tensions are never NaN); its sums are a few loads more.
  const double* v[3] = {Field(s, kOn), Field(s, kTemp), Field(s, kXi)};
  double out[5];
  unit_.SumTelemetry(Field(s, kCount), v, NumCohorts(s), stretch, true, out);
  return unit_.WireStress(out[4]);
}

int SmaBundle::UnitCohort(const double* s, int i) const {
  return static_cast<int>(UnitIndex(s)[i]);
}
bool SmaBundle::UnitOn(const double* s, int i) const {
  return Field(s, kOn)[UnitCohort(s, i)] != 0;
}
double SmaBundle::UnitTemperature(const double* s, int i) const {
  return Field(s, kTemp)[UnitCohort(s, i)];
}
double SmaBundle::UnitXi(const double* s, int i) const { return Field(s, kXi)[UnitCohort(s, i)]; }

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
