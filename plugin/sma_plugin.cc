#include "plugin/sma_plugin.h"

#include <mujoco/mujoco.h>

#include <mutex>
#include <string>
#include <vector>

#include "plugin/sma_instance.h"

namespace recruit::sma {
namespace {

SmaInstance* Get(const mjData* d, int instance) {
  return reinterpret_cast<SmaInstance*>(d->plugin_data[instance]);
}

// The header compiled against must be the library loaded: struct layouts change between releases.
bool VersionMatches() {
  if (mj_version() == mjVERSION_HEADER) return true;
  mju_warning("recruit.sma: built against MuJoCo %d but running %d: rebuild the plugin",
              mjVERSION_HEADER, mj_version());
  return false;
}

int NState(const mjModel* m, int instance) { return SmaInstance::StateSize(m, instance); }

int NSensorData(const mjModel* m, int instance, int sensor_id) {
  int n = 0;
  for (int a = 0; a < m->nactuator; ++a) n += m->actuator_plugin[a] == instance ? 1 : 0;
  return SmaInstance::SensorValues(m, instance) * (n > 0 ? n : 1);
}

int Init(const mjModel* m, mjData* d, int instance) {
  if (!VersionMatches()) return -1;
  auto p = SmaInstance::Create(m, instance);
  if (!p.ok()) {
    mju_warning("%s", p.error().c_str());
    return -1;
  }
  d->plugin_data[instance] = reinterpret_cast<uintptr_t>(p->release());
  return 0;
}

void Destroy(mjData* d, int instance) {
  delete Get(d, instance);
  d->plugin_data[instance] = 0;
}

void Reset(const mjModel* m, mjtNum* plugin_state, void* plugin_data, int instance) {
  const auto* p = static_cast<const SmaInstance*>(plugin_data);
  if (p != nullptr) p->Reset(m, plugin_state);
}

void Compute(const mjModel* m, mjData* d, int instance, int capability_bit) {
  const SmaInstance* p = Get(d, instance);
  if (p == nullptr) return;
  if (capability_bit & mjPLUGIN_ACTUATOR) p->Compute(m, d);
  if (capability_bit & mjPLUGIN_SENSOR) p->Sensor(m, d);
}

void Advance(const mjModel* m, mjData* d, int instance) {
  if (const SmaInstance* p = Get(d, instance)) p->Advance(m, d);
}

}  // namespace

int RegisterSmaPlugin() {
  static int slot = [] {
    std::vector<std::string> keys = BundleConfig::Keys();
    keys.push_back(kSeedKey);
    keys.push_back(kBroadcastPeriodKey);
    std::vector<const char*> attributes;
    for (const std::string& k : keys) attributes.push_back(k.c_str());

    mjpPlugin p;
    mjp_defaultPlugin(&p);
    p.name = kPluginName;
    p.capabilityflags = mjPLUGIN_ACTUATOR | mjPLUGIN_SENSOR;
    p.needstage = mjSTAGE_POS;  // tension needs the tendon length
    p.nattribute = static_cast<int>(attributes.size());
    p.attributes = attributes.data();  // copied by mjp_registerPlugin
    p.nstate = NState;
    p.nsensordata = NSensorData;
    p.init = Init;
    p.destroy = Destroy;
    p.reset = Reset;
    p.compute = Compute;
    p.advance = Advance;
    return mjp_registerPlugin(&p);
  }();
  return slot;
}

}  // namespace recruit::sma
