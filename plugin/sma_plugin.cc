#include "plugin/sma_plugin.h"

#include <atomic>
#include <cmath>
#include <cstring>
#include <mutex>
#include <utility>

#include "common/rng.h"

namespace recruit::sma {
namespace {

// Registry of live plugins keyed by model pointer: a fixed table of slots that callbacks scan
// with atomic loads (no lock, no allocation: sweeps create and destroy plugins on many threads
// while others step). Writers hold a mutex. A slot's plugin is stored before its model, so a
// reader that sees the model sees the plugin.
constexpr int kMaxLivePlugins = 4096;

struct Slot {
  std::atomic<const mjModel*> model{nullptr};
  std::atomic<const SmaPlugin*> plugin{nullptr};
};

struct Registry {
  std::mutex mu;
  Slot slots[kMaxLivePlugins];
  std::atomic<int> used{0};  // slots [0, used) may be occupied
  mjfAct prev_dyn = nullptr, prev_gain = nullptr, prev_bias = nullptr;
};

Registry& GetRegistry() {
  static Registry* r = new Registry;  // never destroyed: callbacks may run during exit
  return *r;
}

const SmaPlugin* Lookup(const mjModel* m) {
  Registry& r = GetRegistry();
  const int n = r.used.load(std::memory_order_acquire);
  for (int i = 0; i < n; ++i) {
    if (r.slots[i].model.load(std::memory_order_acquire) == m) {
      return r.slots[i].plugin.load(std::memory_order_acquire);
    }
  }
  return nullptr;
}

// The newest plugin of a model wins.
bool Register(const mjModel* m, const SmaPlugin* p) {
  Registry& r = GetRegistry();
  std::lock_guard<std::mutex> lock(r.mu);
  const int n = r.used.load(std::memory_order_relaxed);
  int free_slot = -1;
  for (int i = 0; i < n; ++i) {
    const mjModel* mi = r.slots[i].model.load(std::memory_order_relaxed);
    if (mi == m) {
      r.slots[i].plugin.store(p, std::memory_order_release);
      return true;
    }
    if (mi == nullptr && free_slot < 0) free_slot = i;
  }
  if (free_slot < 0) {
    if (n == kMaxLivePlugins) return false;
    free_slot = n;
  }
  r.slots[free_slot].plugin.store(p, std::memory_order_release);
  r.slots[free_slot].model.store(m, std::memory_order_release);
  if (free_slot == n) r.used.store(n + 1, std::memory_order_release);
  return true;
}

void Unregister(const SmaPlugin* p) {
  Registry& r = GetRegistry();
  std::lock_guard<std::mutex> lock(r.mu);
  const int n = r.used.load(std::memory_order_relaxed);
  for (int i = 0; i < n; ++i) {
    if (r.slots[i].plugin.load(std::memory_order_relaxed) == p) {
      r.slots[i].model.store(nullptr, std::memory_order_release);
      r.slots[i].plugin.store(nullptr, std::memory_order_release);
    }
  }
}

mjtNum DynCallback(const mjModel* m, const mjData* d, int id) {
  const SmaPlugin* p = Lookup(m);
  if (p != nullptr && p->BundleOfActuator(id) >= 0) return p->ActDot(d, id);
  mjfAct prev = GetRegistry().prev_dyn;
  return prev != nullptr ? prev(m, d, id) : 0;
}

mjtNum GainCallback(const mjModel* m, const mjData* d, int id) {
  const SmaPlugin* p = Lookup(m);
  if (p != nullptr && p->BundleOfActuator(id) >= 0) return p->Gain(d, id);
  mjfAct prev = GetRegistry().prev_gain;
  return prev != nullptr ? prev(m, d, id) : 0;
}

mjtNum BiasCallback(const mjModel* m, const mjData* d, int id) {
  const SmaPlugin* p = Lookup(m);
  if (p != nullptr && p->BundleOfActuator(id) >= 0) return p->Bias(d, id);
  mjfAct prev = GetRegistry().prev_bias;
  return prev != nullptr ? prev(m, d, id) : 0;
}

std::string Name(const mjModel* m, int type, int id) {
  const char* n = mj_id2name(m, type, id);
  return n != nullptr ? n : "#" + std::to_string(id);
}

const char* DynName(int t) {
  static const char* n[] = {"none", "integrator", "filter", "muscle", "user"};
  return t >= 0 && t <= 4 ? n[t] : "?";
}
const char* GainName(int t) {
  static const char* n[] = {"fixed", "affine", "muscle", "user"};
  return t >= 0 && t <= 3 ? n[t] : "?";
}
const char* BiasName(int t) {
  static const char* n[] = {"none", "affine", "muscle", "user"};
  return t >= 0 && t <= 3 ? n[t] : "?";
}

}  // namespace

void RegisterSmaCallbacks() {
  static std::once_flag once;
  std::call_once(once, [] {
    Registry& r = GetRegistry();
    r.prev_dyn = mjcb_act_dyn;
    r.prev_gain = mjcb_act_gain;
    r.prev_bias = mjcb_act_bias;
    mjcb_act_dyn = DynCallback;
    mjcb_act_gain = GainCallback;
    mjcb_act_bias = BiasCallback;
  });
}

Result<int> SmaPlugin::RequiredUserdata(const mjModel* m) {
  auto p = Build(m);
  if (!p.ok()) return Error{p.error()};
  return (*p)->userdata_end_;
}

Result<std::unique_ptr<SmaPlugin>> SmaPlugin::Create(const mjModel* m) {
  auto p = Build(m);
  if (!p.ok()) return p;
  if (m->nuserdata < (*p)->userdata_end_) {
    return Error{"the model's SMA bundles need <size nuserdata=\"" +
                 std::to_string((*p)->userdata_end_) +
                 "\"/> or more (it has nuserdata=" + std::to_string(m->nuserdata) + ")"};
  }
  RegisterSmaCallbacks();
  if (!Register(m, p->get())) {
    return Error{"SmaPlugin::Create: more than " + std::to_string(kMaxLivePlugins) +
                 " plugins alive at once; destroy plugins of finished runs"};
  }
  (*p)->registered_ = true;
  return p;
}

Result<std::unique_ptr<SmaPlugin>> SmaPlugin::Build(const mjModel* m) {
  if (m == nullptr) return Error{"SmaPlugin::Create: model is null"};
  std::unique_ptr<SmaPlugin> p(new SmaPlugin);
  p->m_ = m;
  p->bundle_of_actuator_.assign(m->nu, -1);
  const std::string prefix = kTextPrefix;

  // Optional start of the plugin's block in userdata.
  int base = 0;
  const int num_id = mj_name2id(m, mjOBJ_NUMERIC, (prefix + "userdata_address").c_str());
  if (num_id >= 0) {
    const double v = m->numeric_data[m->numeric_adr[num_id]];
    if (!(v >= 0) || v != static_cast<int>(v)) {
      return Error{"<custom><numeric name=\"" + prefix +
                   "userdata_address\">: must be a whole number >= 0"};
    }
    base = static_cast<int>(v);
  }

  int address = base;
  for (int t = 0; t < m->ntext; ++t) {
    const std::string tname = Name(m, mjOBJ_TEXT, t);
    if (tname.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string act = tname.substr(prefix.size());
    const int a = mj_name2id(m, mjOBJ_ACTUATOR, act.c_str());
    if (a < 0) {
      std::string names;
      for (int i = 0; i < m->nu; ++i) names += (i ? ", " : "") + Name(m, mjOBJ_ACTUATOR, i);
      return Error{"<custom><text name=\"" + tname + "\">: the model has no actuator named '" +
                   act + "' (actuators: " + (names.empty() ? "none" : names) + ")"};
    }
    const std::string where = "actuator '" + act + "': ";
    if (m->actuator_dyntype[a] != mjDYN_USER) {
      return Error{where + "dyntype must be \"user\" (is \"" + DynName(m->actuator_dyntype[a]) +
                   "\")"};
    }
    if (m->actuator_gaintype[a] != mjGAIN_USER) {
      return Error{where + "gaintype must be \"user\" (is \"" + GainName(m->actuator_gaintype[a]) +
                   "\")"};
    }
    if (m->actuator_biastype[a] != mjBIAS_USER) {
      return Error{where + "biastype must be \"user\" (is \"" + BiasName(m->actuator_biastype[a]) +
                   "\")"};
    }
    if (m->actuator_trntype[a] != mjTRN_TENDON) {
      return Error{where + "must act on a tendon (tendon=\"...\")"};
    }
    if (m->actuator_gear[6 * a] != 1) {
      return Error{where + "gear must be 1 (the bundle's tension is the actuator force)"};
    }
    auto cfg = BundleConfig::FromText(act, std::string(m->text_data + m->text_adr[t]));
    if (!cfg.ok()) return Error{cfg.error()};
    auto bundle = SmaBundle::Create(*cfg, m->opt.timestep);
    if (!bundle.ok()) return Error{bundle.error()};
    const int b = static_cast<int>(p->bundles_.size());
    p->bundle_of_actuator_[a] = b;
    p->actuator_.push_back(a);
    p->tendon_.push_back(m->actuator_trnid[2 * a]);
    p->address_.push_back(address);
    address += bundle->state_size();
    const double ref = std::isnan(cfg->ref_length) ? m->actuator_length0[a] : cfg->ref_length;
    p->ref_length_.push_back(ref);
    p->settled_force_.push_back(bundle->SettledOnTension(cfg->unit.prestretch));
    p->bundles_.push_back(std::move(bundle.value()));
  }
  if (p->bundles_.empty()) {
    return Error{"model has no SMA bundle: add <custom><text name=\"" + prefix +
                 "ACTUATOR\" data=\"...\"/> for a user-type actuator on a tendon"};
  }
  p->userdata_end_ = address;
  return p;
}

SmaPlugin::~SmaPlugin() {
  if (registered_) Unregister(this);
}

int SmaPlugin::BundleIndex(std::string_view actuator_name) const {
  for (int b = 0; b < num_bundles(); ++b) {
    if (bundles_[b].config().actuator == actuator_name) return b;
  }
  return -1;
}

double SmaPlugin::Stretch(const mjData* d, int b) const {
  return bundles_[b].config().unit.prestretch + (d->actuator_length[actuator_[b]] - ref_length_[b]);
}

void SmaPlugin::WriteAct(mjData* d, int b) const {
  const int i = actuator_[b] - (m_->nu - m_->na);
  d->act[i] = static_cast<double>(bundles_[b].OnCount(State(d, b))) / num_units(b);
}

void SmaPlugin::Reset(mjData* d, std::uint64_t seed) const {
  mj_forward(m_, d);  // tendon lengths for the rest states
  for (int b = 0; b < num_bundles(); ++b) {
    bundles_[b].Reset(State(d, b), Rng::DeriveSeed(seed, b), Stretch(d, b));
    WriteAct(d, b);
  }
  mj_forward(m_, d);  // forces and sensors from the reset units
}

Status SmaPlugin::ResetKeyframe(mjData* d, int key, std::uint64_t seed) const {
  if (key < 0 || key >= m_->nkey) {
    return Error{"ResetKeyframe: keyframe " + std::to_string(key) + " does not exist (model has " +
                 std::to_string(m_->nkey) + ")"};
  }
  mj_resetDataKeyframe(m_, d, key);
  Reset(d, seed);
  return Status::Ok();
}

void SmaPlugin::EnsureInitialised(mjData* d) const {
  for (int b = 0; b < num_bundles(); ++b) {
    if (!SmaBundle::Initialized(State(d, b))) {
      bundles_[b].Reset(State(d, b), Rng::DeriveSeed(0, b), Stretch(d, b));
    }
  }
}

Status SmaPlugin::Broadcast(mjData* d, int b, double p_on, double p_off) const {
  if (b < 0 || b >= num_bundles()) {
    return Error{"Broadcast: bundle " + std::to_string(b) + " does not exist (model has " +
                 std::to_string(num_bundles()) + ")"};
  }
  EnsureInitialised(d);
  Status s = bundles_[b].Broadcast(State(d, b), p_on, p_off, Stretch(d, b));
  WriteAct(d, b);
  return s;
}

void SmaPlugin::Advance(mjData* d) const {
  EnsureInitialised(d);
  for (int b = 0; b < num_bundles(); ++b) {
    bundles_[b].Advance(State(d, b), Stretch(d, b), m_->opt.timestep);
    WriteAct(d, b);
  }
}

double SmaPlugin::Bias(const mjData* d, int actuator) const {
  const int b = bundle_of_actuator_[actuator];
  return -bundles_[b].Tension(State(d, b), Stretch(d, b));
}

int SmaPlugin::OnCount(const mjData* d, int b) const { return bundles_[b].OnCount(State(d, b)); }
double SmaPlugin::Force(const mjData* d, int b) const {
  return bundles_[b].Tension(State(d, b), Stretch(d, b));
}
double SmaPlugin::MeanTemperature(const mjData* d, int b) const {
  return bundles_[b].MeanTemperature(State(d, b));
}
double SmaPlugin::MeanXi(const mjData* d, int b) const { return bundles_[b].MeanXi(State(d, b)); }
double SmaPlugin::Heat(const mjData* d, int b) const { return bundles_[b].Heat(State(d, b)); }
int SmaPlugin::NumCohorts(const mjData* d, int b) const {
  return bundles_[b].NumCohorts(State(d, b));
}
bool SmaPlugin::UnitOn(const mjData* d, int b, int i) const {
  return bundles_[b].UnitOn(State(d, b), i);
}
double SmaPlugin::UnitTemperature(const mjData* d, int b, int i) const {
  return bundles_[b].UnitTemperature(State(d, b), i);
}
double SmaPlugin::UnitXi(const mjData* d, int b, int i) const {
  return bundles_[b].UnitXi(State(d, b), i);
}
int SmaPlugin::UnitCohort(const mjData* d, int b, int i) const {
  return bundles_[b].UnitCohort(State(d, b), i);
}

void Step(const mjModel* m, mjData* d, const SmaPlugin& plugin) {
  mj_step(m, d);
  plugin.Advance(d);
}

}  // namespace recruit::sma
