#include "plugin/sma_instance.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <mutex>
#include <set>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>

#include "common/rng.h"
#include "plugin/design_limits.h"

namespace recruit::sma {
namespace {

std::string Short(const std::string& v) { return v.size() <= 40 ? v : v.substr(0, 37) + "..."; }

std::string ActuatorName(const mjModel* m, int a) {
  const char* n = mj_id2name(m, mjOBJ_ACTUATOR, a);
  return n != nullptr && n[0] != '\0' ? n : "#" + std::to_string(a);
}

std::string Config(const mjModel* m, int instance, const char* key) {
  const char* v = mj_getPluginConfig(m, instance, key);
  return v != nullptr ? v : "";
}

Result<std::uint64_t> ParseSeed(const std::string& where, const std::string& v) {
  if (v.empty()) return std::uint64_t{0};
  errno = 0;
  char* end = nullptr;
  const unsigned long long s = std::strtoull(v.c_str(), &end, 10);
  if (v[0] == '-' || end == v.c_str() || *end != '\0' || errno == ERANGE) {
    return Error{where + "config seed=" + Short(v) +
                 " is invalid: must be a whole number in [0, 18446744073709551615]"};
  }
  return static_cast<std::uint64_t>(s);
}

Result<double> ParsePeriod(const std::string& where, const std::string& v) {
  if (v.empty()) return 0.0;
  errno = 0;
  char* end = nullptr;
  const double p = std::strtod(v.c_str(), &end);
  if (end == v.c_str() || *end != '\0' || errno == ERANGE || !(p >= 0 && p <= 1e6)) {
    return Error{where + "config broadcast_period=" + Short(v) +
                 " is invalid: must be a number of seconds in [0, 1e6] (0 = every timestep)"};
  }
  return p;
}

// Index of actuator a among all recruit.sma actuators of m.
int BundleIndexOf(const mjModel* m, int a) {
  int b = 0;
  for (int i = 0; i < a; ++i) {
    if (m->actuator_plugin[i] >= 0 && IsSmaInstance(m, m->actuator_plugin[i])) ++b;
  }
  return b;
}

std::string Fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

// "joint='elbow'" for the actuator's transmission target, to quote it in messages.
std::string Transmission(const mjModel* m, int a) {
  static const char* kinds[] = {"joint", "jointinparent", "slidercrank", "tendon", "site", "body"};
  const int t = m->actuator_trntype[a];
  const char* kind = t >= 0 && t < 6 ? kinds[t] : "transmission";
  const int types[] = {mjOBJ_JOINT, mjOBJ_JOINT, mjOBJ_SITE, mjOBJ_TENDON, mjOBJ_SITE, mjOBJ_BODY};
  const char* name = t >= 0 && t < 6 ? mj_id2name(m, types[t], m->actuator_trnid[2 * a]) : nullptr;
  return std::string(kind) + "='" + (name != nullptr ? name : "?") + "'";
}

Status CheckActuator(const mjModel* m, int a, const std::string& where) {
  if (m->actuator_trntype[a] != mjTRN_TENDON) {
    return Error{where + Transmission(m, a) +
                 " is invalid: must act on a tendon (tendon=\"...\"): a bundle pulls a tendon"};
  }
  if (m->actuator_gear[6 * a] != 1) {
    return Error{where + "gear=" + Fmt("%g", m->actuator_gear[6 * a]) +
                 " is invalid: must be 1 (the bundle's tension is the actuator force)"};
  }
  if (m->actuator_dyntype[a] != mjDYN_NONE || m->actuator_actnum[a] != 0) {
    return Error{where +
                 "must have no activation (no dyntype, actdim 0): unit states live in "
                 "plugin_state"};
  }
  return Status::Ok();
}

// --- Fit check (issue 9 item 8) ---

// True while this thread builds a scratch mjData for a fit check: mj_makeData runs every
// plugin instance's init, which must not start another check.
thread_local bool in_fit_check = false;

struct FitGuard {
  FitGuard() { in_fit_check = true; }
  ~FitGuard() { in_fit_check = false; }
};

// Limited hinge and slide joints whose motion changes tendon t's length (probed at both limits
// and the middle, every other joint at qpos0).
std::vector<int> TendonJoints(const mjModel* m, mjData* d, int t) {
  auto length = [&] {
    mj_kinematics(m, d);
    mj_comPos(m, d);
    mj_tendon(m, d);
    return d->ten_length[t];
  };
  mju_copy(d->qpos, m->qpos0, m->nq);
  const double l0 = length();
  std::vector<int> joints;
  for (int j = 0; j < m->njnt; ++j) {
    const int type = m->jnt_type[j];
    if ((type != mjJNT_HINGE && type != mjJNT_SLIDE) || !m->jnt_limited[j]) continue;
    const int q = m->jnt_qposadr[j];
    bool moves = false;
    for (double f : {0.0, 0.5, 1.0}) {
      d->qpos[q] = m->jnt_range[2 * j] + f * (m->jnt_range[2 * j + 1] - m->jnt_range[2 * j]);
      moves = moves || std::abs(length() - l0) > 1e-9;
    }
    d->qpos[q] = m->qpos0[q];
    if (moves) joints.push_back(j);
  }
  return joints;
}

// The extremes of a smooth length(x) over x in [0, 1]: 33 points (the ends and the middle among
// them), then each interior grid extreme refined by golden-section search between its
// neighbours to 1e-6 of the range. Most tendons are monotone in one joint: 33 kinematics passes
// where a 257-point grid took 257 and was less exact about an interior extreme.
template <typename Length>
std::pair<double, double> LengthRangeOverOneJoint(Length length) {
  constexpr int kPoints = 33;
  double v[kPoints];
  for (int i = 0; i < kPoints; ++i) v[i] = length(i / double(kPoints - 1));
  double lo = *std::min_element(v, v + kPoints), hi = *std::max_element(v, v + kPoints);
  const double h = 1.0 / (kPoints - 1), g = 0.5 * (std::sqrt(5.0) - 1);
  for (int i = 1; i + 1 < kPoints; ++i) {
    for (double sign : {1.0, -1.0}) {  // +1: a minimum, -1: a maximum
      // Strict on the left: a plateau is refined once, not at each of its points.
      if (!(sign * v[i] < sign * v[i - 1] && sign * v[i] <= sign * v[i + 1])) continue;
      double a = (i - 1) * h, b = (i + 1) * h;
      double c = b - g * (b - a), e = a + g * (b - a);
      double fc = sign * length(c), fe = sign * length(e);
      while (b - a > 1e-6) {
        if (fc < fe) {
          b = e, e = c, fe = fc, c = b - g * (b - a), fc = sign * length(c);
        } else {
          a = c, c = e, fc = fe, e = a + g * (b - a), fe = sign * length(e);
        }
      }
      if (sign > 0) {
        lo = std::min({lo, fc, fe});
      } else {
        hi = std::max({hi, -fc, -fe});
      }
    }
  }
  return {lo, hi};
}

// Tendon t's length range over the joints' ranges. One joint: LengthRangeOverOneJoint. More: a
// grid with an odd number of points per joint (so the limits and the middle are on it), 65 x 65
// for two, up to ~4096 in all; beyond 6 joints 4096 seeded random points plus the all-low and
// all-high corners.
std::pair<double, double> LengthRange(const mjModel* m, mjData* d, int t,
                                      const std::vector<int>& joints) {
  const int n = static_cast<int>(joints.size());
  double lo = INFINITY, hi = -INFINITY;
  auto sample = [&](const std::vector<double>& f) {
    mju_copy(d->qpos, m->qpos0, m->nq);
    for (int i = 0; i < n; ++i) {
      const int j = joints[i];
      d->qpos[m->jnt_qposadr[j]] =
          m->jnt_range[2 * j] + f[i] * (m->jnt_range[2 * j + 1] - m->jnt_range[2 * j]);
    }
    mj_kinematics(m, d);
    mj_comPos(m, d);
    mj_tendon(m, d);
    lo = std::min(lo, d->ten_length[t]);
    hi = std::max(hi, d->ten_length[t]);
  };
  std::vector<double> f(n, 0.0);
  if (n == 1) {
    std::tie(lo, hi) = LengthRangeOverOneJoint([&](double x) {
      f[0] = x;
      sample(f);
      return d->ten_length[t];
    });
  } else if (n <= 6) {
    const int points = std::clamp(static_cast<int>(std::pow(4096.0, 1.0 / n)) | 1, 3, 257);
    std::vector<int> idx(n, 0);
    while (true) {
      for (int i = 0; i < n; ++i) f[i] = idx[i] / double(points - 1);
      sample(f);
      int i = 0;
      while (i < n && ++idx[i] == points) idx[i++] = 0;
      if (i == n) break;
    }
  } else {
    Rng rng(1);
    for (int s = 0; s < 4096; ++s) {
      for (int i = 0; i < n; ++i) f[i] = s < 2 ? double(s) : rng.Uniform();
      sample(f);
    }
  }
  return {lo, hi};
}

std::string JointRanges(const mjModel* m, const std::vector<int>& joints) {
  std::string s;
  for (int j : joints) {
    const bool hinge = m->jnt_type[j] == mjJNT_HINGE;
    const double k = hinge ? 180 / mjPI : 1000;
    const char* name = mj_id2name(m, mjOBJ_JOINT, j);
    s += (s.empty() ? "" : ", ") + std::string(name != nullptr ? name : "#" + std::to_string(j)) +
         " " + Fmt("%.4g", k * m->jnt_range[2 * j]) + ".." +
         Fmt("%.4g", k * m->jnt_range[2 * j + 1]) + (hinge ? " deg" : " mm");
  }
  return s;
}

}  // namespace

int SmaPluginSlot() {
  int slot = -1;
  return mjp_getPlugin(kPluginName, &slot) != nullptr ? slot : -1;
}

bool IsSmaInstance(const mjModel* m, int instance) {
  static const int slot = SmaPluginSlot();
  const int s = slot >= 0 ? slot : SmaPluginSlot();
  return instance >= 0 && instance < m->nplugin && s >= 0 && m->plugin[instance] == s;
}

// True the first time (m, instance) is seen with this content: init runs for every mjData, the
// check needs thousands of kinematics passes, so it runs once per distinct compiled model.
static bool FirstCheck(const mjModel* m, int instance) {
  static std::mutex mu;
  static std::set<std::pair<std::size_t, int>> seen;
  const std::size_t h = std::hash<std::string_view>()(
      std::string_view(static_cast<const char*>(m->buffer), static_cast<std::size_t>(m->nbuffer)));
  std::lock_guard<std::mutex> lock(mu);
  return seen.insert({h, instance}).second;
}

Result<std::unique_ptr<SmaInstance>> SmaInstance::Create(const mjModel* m, int instance) {
  // The fit check's scratch mjData only places bodies and tendons: it needs no units (building
  // them was 4 of a run's 12 builds).
  if (in_fit_check) return std::unique_ptr<SmaInstance>();
  auto p = Build(m, instance, true);
  if (p.ok() && FirstCheck(m, instance)) {
    // Design check (issue 26 item 3): one warning per bundle past a long-life limit.
    for (const SmaActuator& a : (*p)->actuators()) {
      const std::string w = DesignWarning(a.model.config());
      if (!w.empty()) mju_warning("recruit.sma %s", w.c_str());
    }
    const std::vector<TendonFit> fits = (*p)->Fit(m);
    for (int k = 0; k < static_cast<int>(fits.size()); ++k) {
      const std::string w = (*p)->FitWarning(m, k, fits[k]);
      if (!w.empty()) mju_warning("%s", w.c_str());
    }
  }
  return p;
}

std::vector<TendonFit> SmaInstance::Fit(const mjModel* m) const {
  FitGuard guard;
  mjData* d = mj_makeData(m);
  std::vector<TendonFit> fits;
  if (d == nullptr) return fits;
  for (const SmaActuator& a : actuators_) {
    TendonFit f;
    const UnitModel& unit = a.model.unit();
    const int n = a.model.num_units();
    const std::vector<int> joints = TendonJoints(m, d, a.tendon);
    f.joints = static_cast<int>(joints.size());
    f.stroke = unit.recoverable_stretch();
    f.on_force = n * a.settled_force;
    f.rated_stress = a.model.limits().max_wire_stress;
    if (f.joints > 0) {
      std::tie(f.length_min, f.length_max) = LengthRange(m, d, a.tendon, joints);
      f.joint_ranges = JointRanges(m, joints);
      const double prestretch = a.model.config().unit.prestretch;
      f.stretch_min = prestretch + (f.length_min - a.ref_length);
      f.stretch_max = prestretch + (f.length_max - a.ref_length);
      const double off = unit.Tension(1.0, f.stretch_max);
      f.off_force = n * off;
      f.off_stress = unit.WireStress(off);
      const double segment = f.stroke / a.model.config().unit.series;
      f.series_needed = std::max(1, static_cast<int>(std::ceil(f.excursion() / segment - 1e-9)));
      f.prestretch_needed = f.series_needed * segment - (f.length_max - a.ref_length);
    }
    fits.push_back(f);
  }
  mj_deleteData(d);
  return fits;
}

std::string SmaInstance::FitWarning(const mjModel* m, int k, const TendonFit& f) const {
  if (f.fits()) return "";
  const SmaActuator& a = actuators_[k];
  auto mm = [](double v) { return Fmt("%.1f", 1000 * v); };
  // Short: mj_loadXML keeps about 500 characters of warnings for all bundles together.
  std::string w = "recruit.sma actuator '" + ActuatorName(m, a.actuator) + "': tendon excursion " +
                  mm(f.excursion()) + " mm over " + f.joint_ranges.substr(0, 40) +
                  ", unit stroke " + mm(f.stroke) + " mm, extension " + mm(f.stretch_min) + ".." +
                  mm(f.stretch_max) + " mm:";
  if (f.blocks()) {
    w += " off units pull " + Fmt("%.3g", f.off_force) + " N (" + Fmt("%.0f", f.off_stress / 1e6) +
         " MPa): will block the joint;";
  }
  if (f.slack()) w += " on units slack over " + mm(-f.stretch_min) + " mm;";
  w += " fit: series=" + std::to_string(f.series_needed) +
       " prestretch=" + Fmt("%.3g", f.prestretch_needed);
  return w;
}

Result<std::unique_ptr<SmaInstance>> SmaInstance::Build(const mjModel* m, int instance,
                                                        bool check_actuators) {
  if (!IsSmaInstance(m, instance)) {
    return Error{"plugin instance " + std::to_string(instance) + " is not a recruit.sma instance"};
  }
  std::unique_ptr<SmaInstance> p(new SmaInstance);
  p->instance_ = instance;
  std::vector<std::pair<std::string, std::string>> pairs;
  for (const std::string& key : BundleConfig::Keys()) {
    pairs.emplace_back(key, Config(m, instance, key.c_str()));
  }
  int offset = 0;
  for (int a = 0; a < m->nactuator; ++a) {
    if (m->actuator_plugin[a] != instance) continue;
    const std::string name = ActuatorName(m, a);
    const std::string where = "recruit.sma actuator '" + name + "': ";
    if (p->actuators_.empty()) {
      auto seed = ParseSeed(where, Config(m, instance, kSeedKey));
      if (!seed.ok()) return Error{seed.error()};
      auto period = ParsePeriod(where, Config(m, instance, kBroadcastPeriodKey));
      if (!period.ok()) return Error{period.error()};
      p->seed_ = *seed;
      p->broadcast_period_ = *period;
    }
    if (check_actuators) {
      Status ok = CheckActuator(m, a, where);
      if (!ok.ok()) return Error{ok.error()};
    }
    auto cfg = BundleConfig::FromPairs(name, where + "config ", pairs);
    if (!cfg.ok()) return Error{cfg.error()};
    auto bundle = SmaBundle::Create(*cfg, m->opt.timestep);
    if (!bundle.ok()) return Error{where + bundle.error()};
    SmaActuator act{a, m->actuator_trnid[2 * a], BundleIndexOf(m, a), offset, 0,
                    0, std::move(bundle).value()};
    act.ref_length = std::isnan(cfg->ref_length) ? m->actuator_length0[a] : cfg->ref_length;
    act.settled_force = act.model.SettledOnTension(cfg->unit.prestretch);
    offset += kSlots + act.model.state_size();
    p->actuators_.push_back(std::move(act));
  }
  if (p->actuators_.empty()) {
    return Error{"recruit.sma instance " + std::to_string(instance) +
                 " drives no actuator: use it in an <actuator><plugin ... tendon=\"...\"/>"};
  }
  p->state_size_ = offset;
  // The sensor callback writes these every step: found once instead of scanning every sensor
  // (not for StateSize: the compiler asks it before the sensors are filled in).
  for (int j = 0; check_actuators && j < m->nsensor; ++j) {
    if (m->sensor_plugin[j] == instance) p->sensor_adr_.push_back(m->sensor_adr[j]);
  }
  return p;
}

int SmaInstance::StateSize(const mjModel* m, int instance) {
  auto p = Build(m, instance, false);
  return p.ok() ? (*p)->state_size_ : 0;
}

void SmaInstance::Reset(const mjModel* m, double* block) const {
  for (const SmaActuator& a : actuators_) {
    double* slots = block + a.offset;
    slots[kNextBroadcastSlot] = 0;
    slots[1] = 0;
    const double stretch =
        a.model.config().unit.prestretch + (m->actuator_length0[a.actuator] - a.ref_length);
    a.model.Reset(slots + kSlots, Rng::DeriveSeed(seed_, a.bundle), stretch);
  }
}

void SmaInstance::Compute(const mjModel* m, mjData* d) const {
  for (int k = 0; k < static_cast<int>(actuators_.size()); ++k) {
    const int a = actuators_[k].actuator;
    const double stretch = Stretch(k, Length(m, d, a));
    // The sensor (position stage) usually summed this tension already in this mj_forward.
    d->actuator_force[m->actuator_outadr[a]] =
        -actuators_[k].model.TakeTension(State(d->plugin_state, m, k), stretch);
  }
}

void SmaInstance::Advance(const mjModel* m, mjData* d) const {
  const double h = m->opt.timestep;
  const double t = d->time - h;  // start of the step just integrated
  for (int k = 0; k < static_cast<int>(actuators_.size()); ++k) {
    const SmaActuator& act = actuators_[k];
    const int a = act.actuator;
    const int out = m->actuator_outadr[a];
    // The tendon's length at the end of the step (first order): the units' new state goes with
    // the new pose, as under RK4.
    const double stretch = Stretch(k, d->actuator_length[out] + h * d->actuator_velocity[out]);
    double* s = State(d->plugin_state, m, k);
    double& next = NextBroadcast(d, m, k);
    const double u = d->ctrl[m->actuator_ctrladr[a]];
    if (t + 0.5 * h >= next) {
      if (u != 0 && std::isfinite(u)) {
        const double p = std::min(1.0, std::abs(u));
        (void)act.model.Broadcast(s, u > 0 ? p : 0.0, u < 0 ? p : 0.0, stretch);  // p in [0, 1]
      }
      next = broadcast_period_ > 0
                 ? (std::floor((t + 0.5 * h) / broadcast_period_) + 1) * broadcast_period_
                 : t + h;
    }
    act.model.Advance(s, stretch, h);
  }
}

void SmaInstance::Sensor(const mjModel* m, mjData* d) const {
  for (const int adr : sensor_adr_) {
    double* out = d->sensordata + adr;
    for (int k = 0; k < static_cast<int>(actuators_.size()); ++k) {
      const SmaActuator& act = actuators_[k];
      double* s = State(d->plugin_state, m, k);
      const double stretch = Stretch(k, Length(m, d, act.actuator));
      // Keeps the tension for the actuator's force, computed later in the same mj_forward.
      const SmaBundle::Summary sum = act.model.SummarizeAndKeep(s, stretch);
      out[kSensorValues * k + 0] = sum.on_count;
      out[kSensorValues * k + 1] = sum.tension;
      out[kSensorValues * k + 2] = sum.mean_temperature;
      out[kSensorValues * k + 3] = sum.mean_xi;
    }
  }
}

}  // namespace recruit::sma
