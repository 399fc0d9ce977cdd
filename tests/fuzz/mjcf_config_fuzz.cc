// Fuzz target: a recruit.sma <config> through MuJoCo's loader, as `recruit simulate` loads a
// model: the values become <config key value> of the plugin instance on the isometric bench
// (one value per line, in the order of the plugin's keys: BundleConfig::Keys(), then seed and
// broadcast_period; "" leaves a key unset). This reaches the plugin's whole configuration path
// (SmaInstance::Create: BundleConfig::FromPairs, the seed and period parsers, the actuator
// checks). A model that loads is made into data and stepped with both broadcasts.
#include <mujoco/mujoco.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "common/mujoco_load.h"
#include "plugin/bundle_config.h"
#include "plugin/sma_instance.h"

namespace {

std::string XmlEscaped(const std::string& v) {
  std::string out;
  for (char c : v) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        if (static_cast<unsigned char>(c) >= 0x20) out += c;  // XML allows no control bytes
    }
  }
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::vector<std::string> kKeys = [] {
    mju_user_warning = [](const char*) {};  // load errors are expected; keep the log short
    std::vector<std::string> k = recruit::sma::BundleConfig::Keys();
    k.push_back(recruit::sma::kSeedKey);
    k.push_back(recruit::sma::kBroadcastPeriodKey);
    return k;
  }();
  const std::string in(reinterpret_cast<const char*>(data), size);
  std::string config;
  size_t start = 0;
  for (const std::string& key : kKeys) {
    if (start > in.size()) break;
    size_t end = in.find('\n', start);
    if (end == std::string::npos) end = in.size();
    const std::string value = XmlEscaped(in.substr(start, end - start));
    if (!value.empty()) config += "<config key=\"" + key + "\" value=\"" + value + "\"/>";
    start = end + 1;
  }
  const std::string xml = R"(<mujoco model="fuzz">
  <compiler autolimits="true"/>
  <option timestep="0.001" integrator="Euler"/>
  <extension><plugin plugin="recruit.sma"><instance name="units">)" +
                          config + R"(</instance></plugin></extension>
  <worldbody>
    <site name="anchor" pos="0 0 0.2"/>
    <body name="load_cell" pos="0.1 0 0.2">
      <joint name="load_cell" type="slide" axis="1 0 0" stiffness="1e6" damping="4000"/>
      <geom type="box" size="0.01 0.02 0.02" mass="5"/>
      <site name="hook"/>
    </body>
  </worldbody>
  <tendon><spatial name="bundle"><site site="anchor"/><site site="hook"/></spatial></tendon>
  <actuator><plugin name="bundle" instance="units" tendon="bundle" ctrlrange="-1 1"/></actuator>
  <sensor><plugin name="truth" instance="units"/></sensor>
</mujoco>)";
  auto m = recruit::LoadModelFromString(xml, "fuzz.xml");
  if (!m.ok()) return 0;
  recruit::DataPtr d(mj_makeData(m->get()));
  if (!d) return 0;
  for (int k = 0; k < 6; ++k) {
    d->ctrl[0] = k < 3 ? 0.5 : -0.5;
    mj_step(m->get(), d.get());
  }
  return 0;
}
