#include "plugin/sma_instance.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <string>
#include <utility>

#include "common/rng.h"

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

Status CheckActuator(const mjModel* m, int a, const std::string& where) {
  if (m->actuator_trntype[a] != mjTRN_TENDON) {
    return Error{where + "must act on a tendon (tendon=\"...\"): a bundle pulls a tendon"};
  }
  if (m->actuator_gear[6 * a] != 1) {
    return Error{where + "gear=" + std::to_string(m->actuator_gear[6 * a]) +
                 " is invalid: must be 1 (the bundle's tension is the actuator force)"};
  }
  if (m->actuator_dyntype[a] != mjDYN_NONE || m->actuator_actnum[a] != 0) {
    return Error{where +
                 "must have no activation (no dyntype, actdim 0): unit states live in "
                 "plugin_state"};
  }
  return Status::Ok();
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

Result<std::unique_ptr<SmaInstance>> SmaInstance::Create(const mjModel* m, int instance) {
  return Build(m, instance, true);
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
    d->actuator_force[m->actuator_outadr[a]] =
        -actuators_[k].model.Tension(State(d->plugin_state, m, k), stretch);
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
        act.model.Broadcast(s, u > 0 ? p : 0.0, u < 0 ? p : 0.0, stretch);
      }
      next = broadcast_period_ > 0
                 ? (std::floor((t + 0.5 * h) / broadcast_period_) + 1) * broadcast_period_
                 : t + h;
    }
    act.model.Advance(s, stretch, h);
  }
}

void SmaInstance::Sensor(const mjModel* m, mjData* d) const {
  for (int j = 0; j < m->nsensor; ++j) {
    if (m->sensor_plugin[j] != instance_) continue;
    double* out = d->sensordata + m->sensor_adr[j];
    for (int k = 0; k < static_cast<int>(actuators_.size()); ++k) {
      const SmaActuator& act = actuators_[k];
      const double* s = State(d->plugin_state, m, k);
      const double stretch = Stretch(k, Length(m, d, act.actuator));
      out[kSensorValues * k + 0] = act.model.OnCount(s);
      out[kSensorValues * k + 1] = act.model.Tension(s, stretch);
      out[kSensorValues * k + 2] = act.model.MeanTemperature(s);
      out[kSensorValues * k + 3] = act.model.MeanXi(s);
    }
  }
}

}  // namespace recruit::sma
