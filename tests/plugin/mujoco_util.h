// Helpers of the engine-plugin tests: loading the plugin library, inline bundle models, copies
// of plugin_state, and capturing mju_warning.
#pragma once

#include <mujoco/mujoco.h>

#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#include "common/mujoco_load.h"
#include "common/mujoco_ptr.h"

namespace recruit::sma::testing {

using ::recruit::DataPtr;
using ::recruit::ModelPtr;

// Loads librecruit_sma.so the way any MuJoCo program would (once per process). Programs that
// link the library need not call it (its constructor registers the plugin).
inline void LoadPluginLibrary() {
#ifdef RECRUIT_SMA_LIBRARY
  static std::once_flag once;
  std::call_once(once, [] { mj_loadPluginLibrary(RECRUIT_SMA_LIBRARY); });
#endif
}

inline std::string ConfigXml(const std::string& key, const std::string& value) {
  return "<config key=\"" + key + "\" value=\"" + value + "\"/>";
}

// An isometric bench: one bundle (explicit instance "units", actuator `name`) pulls a tendon
// from a fixed anchor to a load cell on a stiff slide joint, or, with `fixed`, to a second
// world site (no degree of freedom: the tendon length never changes).
struct Bench {
  std::string config;                                 // <config> elements of the instance
  std::string name = "bundle";                        // actuator name
  std::string target = "tendon=\"bundle\"";           // the actuator's transmission
  std::string actuator_extra = "ctrlrange=\"-1 1\"";  // more actuator attributes
  std::string integrator = "Euler";
  bool fixed = false;
};

inline std::string BenchXml(const Bench& b) {
  const std::string hook = b.fixed ? R"(<site name="hook" pos="0.1 0 0.2"/>)"
                                   : R"(<body name="load_cell" pos="0.1 0 0.2">
      <joint name="load_cell" type="slide" axis="1 0 0" stiffness="1e6" damping="4000"/>
      <geom type="box" size="0.01 0.02 0.02" mass="5"/>
      <site name="hook"/>
    </body>)";
  return R"(<mujoco model="bench">
  <compiler autolimits="true"/>
  <option timestep="0.001" integrator=")" +
         b.integrator + R"("/>
  <extension><plugin plugin="recruit.sma"><instance name="units">)" +
         b.config + R"(</instance></plugin></extension>
  <worldbody>
    <site name="anchor" pos="0 0 0.2"/>
    )" + hook +
         R"(
  </worldbody>
  <tendon><spatial name="bundle"><site site="anchor"/><site site="hook"/></spatial></tendon>
  <actuator>
    <plugin name=")" +
         b.name + "\" instance=\"units\" " + b.target + " " + b.actuator_extra + R"(/>
  </actuator>
  <sensor><plugin name="truth" instance="units"/></sensor>
</mujoco>)";
}

// Compiles `xml` with MuJoCo's own loader (the plugin library must be loaded).
inline Result<ModelPtr> Load(const std::string& xml) {
  LoadPluginLibrary();
  return LoadModelFromString(xml);
}

inline std::vector<double> PluginState(const mjModel* m, const mjData* d) {
  return std::vector<double>(d->plugin_state, d->plugin_state + m->npluginstate);
}

// Bitwise equality of n doubles (NaN-safe, distinguishes -0 and +0).
inline bool SameBits(const double* a, const double* b, long n) {
  return n == 0 || std::memcmp(a, b, sizeof(double) * static_cast<size_t>(n)) == 0;
}

// Collects mju_warning texts while alive (tests in one thread only).
class WarningCapture {
 public:
  WarningCapture() : old_(mju_user_warning) {
    Texts().clear();
    mju_user_warning = [](const char* msg) { Texts().emplace_back(msg); };
  }
  ~WarningCapture() { mju_user_warning = old_; }
  const std::vector<std::string>& texts() const { return Texts(); }
  std::string joined() const {
    std::string s;
    for (const std::string& t : Texts()) s += t + "\n";
    return s;
  }

 private:
  static std::vector<std::string>& Texts() {
    static std::vector<std::string> t;
    return t;
  }
  void (*old_)(const char*);
};

}  // namespace recruit::sma::testing
