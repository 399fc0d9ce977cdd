// Loading MJCF from strings and owning MuJoCo objects in the plugin's tests.
#pragma once

#include <mujoco/mujoco.h>

#include <cstring>
#include <memory>
#include <string>

#include "common/mujoco_ptr.h"

namespace recruit::sma::testing {

using ::recruit::DataPtr;
using ::recruit::ModelPtr;

// Compiles `xml`; on failure returns null and puts MuJoCo's message in *error.
inline ModelPtr LoadXmlString(const std::string& xml, std::string* error = nullptr) {
  auto vfs = std::make_unique<mjVFS>();  // about 2 MB: not on the stack
  mj_defaultVFS(vfs.get());
  mj_makeEmptyFileVFS(vfs.get(), "model.xml", static_cast<int>(xml.size()));
  std::memcpy(vfs->filedata[0], xml.data(), xml.size());
  char err[1000] = "";
  ModelPtr m(mj_loadXML("model.xml", vfs.get(), err, sizeof err));
  mj_deleteVFS(vfs.get());
  if (error != nullptr) *error = err;
  return m;
}

inline ModelPtr LoadXmlFile(const std::string& path, std::string* error = nullptr) {
  char err[1000] = "";
  ModelPtr m(mj_loadXML(path.c_str(), nullptr, err, sizeof err));
  if (error != nullptr) *error = err;
  return m;
}

inline DataPtr MakeData(const mjModel* m) { return DataPtr(mj_makeData(m)); }

// The isometric bench with the given <text> data, nuserdata, extra actuator attributes and
// integrator, for tests that vary one thing.
inline std::string BenchXml(const std::string& data = "units=60", int nuserdata = 488,
                            const std::string& actuator_extra = "",
                            const std::string& integrator = "Euler") {
  return R"(<mujoco>
  <compiler autolimits="true"/>
  <option timestep="0.001" integrator=")" +
         integrator + R"("/>
  <size nuserdata=")" +
         std::to_string(nuserdata) + R"("/>
  <custom><text name="recruit.sma.bundle" data=")" +
         data + R"("/></custom>
  <worldbody>
    <site name="anchor" pos="0 0 0.2"/>
    <body name="load_cell" pos="0.1 0 0.2">
      <joint name="load_cell" type="slide" axis="1 0 0" stiffness="1e6" damping="4000"/>
      <geom type="box" size="0.01 0.02 0.02" mass="5"/>
      <site name="hook"/>
    </body>
  </worldbody>
  <tendon><spatial name="bundle"><site site="anchor"/><site site="hook"/></spatial></tendon>
  <actuator>
    <general name="bundle" tendon="bundle" dyntype="user" gaintype="user" biastype="user" )" +
         actuator_extra + R"(/>
  </actuator>
  <keyframe><key name="stretched" qpos="0.0005"/></keyframe>
</mujoco>)";
}

}  // namespace recruit::sma::testing
