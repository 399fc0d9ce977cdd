#include "plugin/sma_instance.h"

#include <mujoco/mjxmacro.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>
#include <vector>

#include "common/rng.h"
#include "common/short_text.h"
#include "plugin/design_limits.h"
#include "plugin/tendon_range.h"

namespace recruit::sma {
namespace {

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
    return Error{where + "config seed=" + ShortText(v) +
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
    return Error{where + "config broadcast_period=" + ShortText(v) +
                 " is invalid: must be a number of seconds in [0, 1e6] (0 = every timestep)"};
  }
  return p;
}

// An instance's config values: every BundleConfig key's, the seed's and the broadcast period's.
struct ConfigValues {
  std::vector<std::pair<std::string, std::string>> pairs;
  std::string seed, period;
};

// The instance's config values, kept per process by the instance's raw attribute bytes in the
// model (mjModel.plugin_attr: the values MuJoCo's mj_getPluginConfig reads, ~1000 instructions a
// key): the same bytes give the same values.
std::shared_ptr<const ConfigValues> Values(const mjModel* m, int instance) {
  static std::mutex mu;
  static std::map<std::string, std::shared_ptr<const ConfigValues>> kept;
  auto read = [&] {
    auto v = std::make_shared<ConfigValues>();
    for (const std::string& k : BundleConfig::Keys()) {
      v->pairs.emplace_back(k, Config(m, instance, k.c_str()));
    }
    v->seed = Config(m, instance, kSeedKey);
    v->period = Config(m, instance, kBroadcastPeriodKey);
    return v;
  };
  const mjtSize begin = m->plugin_attradr[instance];
  const mjtSize end = instance + 1 < m->nplugin ? m->plugin_attradr[instance + 1] : m->npluginattr;
  if (!(0 <= begin && begin <= end && end <= m->npluginattr)) return read();  // not kept
  std::string key(m->plugin_attr + begin, m->plugin_attr + end);
  {
    std::lock_guard<std::mutex> guard(mu);
    if (auto it = kept.find(key); it != kept.end()) return it->second;
  }
  auto v = read();
  std::lock_guard<std::mutex> guard(mu);
  if (kept.size() >= 4096) kept.clear();  // a bound for long-lived processes over many designs
  return kept.emplace(std::move(key), std::move(v)).first->second;
}

// A bundle's parsed config and its units' settled on-tension at the config's prestretch, kept
// per process by the exact text they are made of (actuator name, message prefix, every key and
// value): a run builds each instance 4-8 times (the compiler's and loader's size queries, one per
// mjData), and parsing with its physics check and the settling loop were ~2/3 of each build.
struct ParsedConfig {
  Result<BundleConfig> config;
  double settled_force = std::nan("");  // NaN until the first build computes it
};

std::shared_ptr<ParsedConfig> Parse(const std::string& name, const std::string& where,
                                    const std::vector<std::pair<std::string, std::string>>& pairs,
                                    std::mutex** lock) {
  static std::mutex mu;
  static std::map<std::string, std::shared_ptr<ParsedConfig>> kept;
  std::string key = name + '\0' + where;
  for (const auto& [k, v] : pairs) key += '\0' + k + '\0' + v;
  *lock = &mu;
  {
    std::lock_guard<std::mutex> guard(mu);
    if (auto it = kept.find(key); it != kept.end()) return it->second;
  }
  auto parsed =
      std::make_shared<ParsedConfig>(ParsedConfig{BundleConfig::FromPairs(name, where, pairs)});
  std::lock_guard<std::mutex> guard(mu);
  if (kept.size() >= 4096) kept.clear();  // a bound for long-lived processes over many designs
  return kept.emplace(std::move(key), std::move(parsed)).first->second;
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
  const double gear = m->actuator_gear[6 * a];
  if (!(gear > 0 && std::isfinite(gear))) {
    return Error{where + "gear=" + Fmt("%g", gear) +
                 " is invalid: must be > 0 (a transmission ratio: the units stretch gear x the "
                 "tendon's length change and the tendon gets gear x their tension)"};
  }
  if (m->actuator_dyntype[a] != mjDYN_NONE || m->actuator_actnum[a] != 0) {
    return Error{where +
                 "must have no activation (no dyntype, actdim 0): unit states live in "
                 "plugin_state"};
  }
  return Status::Ok();
}

// --- Fit check ---

// True while this thread builds a scratch mjData for a fit check: mj_makeData runs every
// plugin instance's init, which must not start another check.
thread_local bool in_fit_check = false;

struct FitGuard {
  FitGuard() { in_fit_check = true; }
  ~FitGuard() { in_fit_check = false; }
};

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

// True if the pointer field `name` of mjModel holds asset data that only collision and rendering
// read (meshes, skins, height fields, textures, bounding volumes, octrees): nothing the load
// checks compute from (designs, kinematics and tendons).
static bool AssetData(std::string_view name) {
  for (std::string_view prefix : {"mesh_", "skin_", "hfield_", "tex_", "bvh_", "oct_"}) {
    if (name.substr(0, prefix.size()) == prefix) return true;
  }
  return false;
}

// Content hash of what the load checks read: every size and every array of the model but the
// asset data above. A MyoSuite arm's buffer is mostly its 74 meshes: hashing all of it, once per
// bundle and mjData, was half of a short run's instructions (2.2 of 4.2 G).
static std::size_t ModelContentHash(const mjModel* m) {
  std::size_t h = 0;
  auto mix = [&h](const void* p, std::size_t bytes) {
    const std::size_t x =
        std::hash<std::string_view>()(std::string_view(static_cast<const char*>(p), bytes));
    h = (h ^ x) * 0x100000001b3ull + 0x9e3779b97f4a7c15ull;
  };
  long long sizes[] = {
#define X(name) static_cast<long long>(m->name),
      MJMODEL_SIZES
#undef X
  };
  mix(sizes, sizeof sizes);
  MJMODEL_POINTERS_PREAMBLE(m)
  (void)nuser_body, (void)nuser_jnt, (void)nuser_geom, (void)nuser_site, (void)nuser_cam;
  (void)nuser_tendon, (void)nuser_actuator, (void)nuser_sensor, (void)nq, (void)nv, (void)na;
  (void)nu, (void)nmocap, (void)nplastic;
#define X(type, name, nr, nc) \
  if (!AssetData(#name)) mix(m->name, sizeof(type) * static_cast<std::size_t>(m->nr) * (nc));
#define XNV X
  MJMODEL_POINTERS
#undef XNV
#undef X
  return h;
}

// True the first time (m, instance) is seen with this content: init runs for every mjData, the
// check needs thousands of kinematics passes, so it runs once per distinct compiled model.
static bool FirstCheck(const mjModel* m, int instance) {
  static std::mutex mu;
  static std::set<std::pair<std::size_t, int>> seen;
  const std::size_t h = ModelContentHash(m);
  std::lock_guard<std::mutex> lock(mu);
  return seen.insert({h, instance}).second;
}

Result<std::unique_ptr<SmaInstance>> SmaInstance::Create(const mjModel* m, int instance) {
  // The fit check's scratch mjData only places bodies and tendons: it needs no units (building
  // them was 4 of a run's 12 builds).
  if (in_fit_check) return std::unique_ptr<SmaInstance>();
  auto p = Build(m, instance, true);
  if (p.ok() && FirstCheck(m, instance)) {
    for (const std::string& w : (*p)->LoadWarnings(m)) mju_warning("%s", w.c_str());
  }
  return p;
}

std::vector<std::string> SmaInstance::LoadWarnings(const mjModel* m) const {
  // Kept per distinct model and instance: the fit check samples the joints thousands of times,
  // and every run of a model asks again for what its first load printed.
  static std::mutex mu;
  static std::map<std::pair<std::size_t, int>, std::vector<std::string>> kept;
  const auto key = std::make_pair(ModelContentHash(m), instance_);
  {
    std::lock_guard<std::mutex> lock(mu);
    if (auto it = kept.find(key); it != kept.end()) return it->second;
  }
  std::vector<std::string> out = ComputeLoadWarnings(m);
  std::lock_guard<std::mutex> lock(mu);
  kept.emplace(key, out);
  return out;
}

std::vector<std::string> SmaInstance::ComputeLoadWarnings(const mjModel* m) const {
  std::vector<std::string> out;
  // The design against the wire's long-life limits: one warning per bundle past one.
  for (const SmaActuator& a : actuators_) {
    const std::string w = DesignWarning(a.model.config());
    if (!w.empty()) out.push_back("recruit.sma " + w);
  }
  const std::vector<TendonFit> fits = Fit(m);
  for (int k = 0; k < static_cast<int>(fits.size()); ++k) {
    const std::string w = FitWarning(m, k, fits[k]);
    if (!w.empty()) out.push_back(w);
  }
  return out;
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
    const TendonRange range = SampleTendonRange(m, d, a.tendon);
    f.joints = static_cast<int>(range.joints.size());
    f.gear = a.gear;
    f.stroke = unit.recoverable_stretch();
    f.on_force = n * a.settled_force;
    f.rated_stress = a.model.limits().max_wire_stress;
    if (f.joints > 0) {
      f.length_min = range.length_min;
      f.length_max = range.length_max;
      f.joint_ranges = JointRangeText(m, range.joints, range.usable_lo, range.usable_hi);
      for (const TendonJump& jump : range.jumps) {
        f.jumps += (f.jumps.empty() ? "" : "; ") + JumpText(m, jump);
      }
      f.num_jumps = static_cast<int>(range.jumps.size());
      // The units work in actuator length (gear x tendon length).
      const double prestretch = a.model.config().unit.prestretch;
      f.stretch_min = prestretch + (a.gear * f.length_min - a.ref_length);
      f.stretch_max = prestretch + (a.gear * f.length_max - a.ref_length);
      const double off = unit.Tension(1.0, f.stretch_max);
      f.off_force = n * off;
      f.off_stress = unit.WireStress(off);
      const double segment = f.stroke / a.model.config().unit.series;
      f.series_needed =
          std::max(1, static_cast<int>(std::ceil(a.gear * f.excursion() / segment - 1e-9)));
      f.prestretch_needed = f.series_needed * segment - (a.gear * f.length_max - a.ref_length);
    }
    fits.push_back(f);
  }
  mj_deleteData(d);
  return fits;
}

std::string ClipEntries(const std::string& s, size_t max) {
  if (s.size() <= max) return s;
  size_t cut = std::string::npos;
  for (const char* sep : {"; ", ", "}) {
    const size_t at = s.rfind(sep, max);
    if (at != std::string::npos && at > 0 && (cut == std::string::npos || at > cut)) cut = at;
  }
  return cut == std::string::npos ? s.substr(0, max) + "..." : s.substr(0, cut + 2) + "...";
}

std::string SmaInstance::FitWarning(const mjModel* m, int k, const TendonFit& f) const {
  if (f.fits() && f.num_jumps == 0) return "";
  const SmaActuator& a = actuators_[k];
  auto mm = [](double v) { return Fmt("%.1f", 1000 * v); };
  // Short: mj_loadXML keeps about 500 characters of warnings for all bundles together.
  std::string w = "recruit.sma actuator '" + ActuatorName(m, a.actuator) + "': ";
  if (f.num_jumps > 0) {
    w += "tendon path jumps at " + ClipEntries(f.jumps, 60) + ": usable " +
         ClipEntries(f.joint_ranges, 48) + ";";
    if (f.fits()) return w;
    w += " ";
  }
  w += "tendon excursion " + mm(f.excursion()) + " mm over " + ClipEntries(f.joint_ranges, 48) +
       (f.gear != 1 ? " (gear " + Fmt("%g", f.gear) + ")" : "") + ", unit stroke " + mm(f.stroke) +
       " mm, extension " + mm(f.stretch_min) + ".." + mm(f.stretch_max) + " mm:";
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
  const std::shared_ptr<const ConfigValues> values = Values(m, instance);
  const std::vector<std::pair<std::string, std::string>>& pairs = values->pairs;
  int offset = 0;
  for (int a = 0; a < m->nactuator; ++a) {
    if (m->actuator_plugin[a] != instance) continue;
    const std::string name = ActuatorName(m, a);
    const std::string where = "recruit.sma actuator '" + name + "': ";
    if (p->actuators_.empty()) {
      auto seed = ParseSeed(where, values->seed);
      if (!seed.ok()) return Error{seed.error(), seed.code()};
      auto period = ParsePeriod(where, values->period);
      if (!period.ok()) return Error{period.error(), period.code()};
      p->seed_ = *seed;
      p->broadcast_period_ = *period;
    }
    if (check_actuators) {
      Status ok = CheckActuator(m, a, where);
      if (!ok.ok()) return Error{ok.error(), ok.code()};
    }
    std::mutex* mu = nullptr;
    const std::shared_ptr<ParsedConfig> parsed = Parse(name, where + "config ", pairs, &mu);
    const Result<BundleConfig>& cfg = parsed->config;
    if (!cfg.ok()) return Error{cfg.error(), cfg.code()};
    auto bundle = SmaBundle::Create(*cfg, m->opt.timestep);
    if (!bundle.ok()) return Error{where + bundle.error(), bundle.code()};
    SmaActuator act{a, m->actuator_trnid[2 * a], BundleIndexOf(m, a), offset, 0,
                    0, std::move(bundle).value()};
    // In actuator length (gear x tendon length), as the units see it; ref_length is a tendon
    // length.
    act.gear = m->actuator_gear[6 * a];
    act.ref_length =
        std::isnan(cfg->ref_length) ? m->actuator_length0[a] : act.gear * cfg->ref_length;
    {
      std::lock_guard<std::mutex> guard(*mu);
      if (std::isnan(parsed->settled_force)) {
        parsed->settled_force = act.model.SettledOnTension(cfg->unit.prestretch);
      }
      act.settled_force = parsed->settled_force;
    }
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

int SmaInstance::SensorValues(const mjModel* m, int instance) {
  auto p = Build(m, instance, false);
  return p.ok() ? (*p)->sensor_values() : kSensorValues;
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
    // The telemetry a host asked for (ObserveEachStep) is read after mj_step, at the tendon's
    // length as it is until the next mj_forward.
    act.model.Advance(s, stretch, h, Stretch(k, d->actuator_length[out]));
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
      const int stride = sensor_values();
      out[stride * k + 0] = sum.on_count;
      out[stride * k + 1] = sum.tension;
      out[stride * k + 2] = sum.mean_temperature;
      out[stride * k + 3] = sum.mean_xi;
      if (stride == kFailureSensorValues) {
        const SmaBundle::FailureCounts f = act.model.Failures(s);
        out[stride * k + 4] = f.working;
        out[stride * k + 5] = f.open;
        out[stride * k + 6] = f.stuck;
      }
    }
  }
}

}  // namespace recruit::sma
