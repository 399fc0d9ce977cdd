// recruit.sma: the MuJoCo engine plugin (mjpPlugin with the actuator and sensor capabilities).
// Loading librecruit_sma.so registers it (mj_loadPluginLibrary, dlopen, mujoco.PLUGINS_DIR or
// linking the library); RegisterSmaPlugin() does the same by hand and is idempotent.
//
//   <extension><plugin plugin="recruit.sma"/></extension>
//   <actuator>
//     <plugin name="flexor" plugin="recruit.sma" tendon="flexor_tendon" ctrlrange="-1 1">
//       <config key="units" value="60"/>
//     </plugin>
//   </actuator>
//
// ctrl is a signed broadcast: at each broadcast instant (every `broadcast_period` s, 0 = every
// timestep) an off unit turns on with probability ctrl (ctrl > 0) or an on unit turns off with
// probability -ctrl (ctrl < 0); ctrl = 0 changes nothing. plugin/README.md has every key, the
// state layout and the sensor.
#pragma once

namespace recruit::sma {

// Registers recruit.sma with MuJoCo (once per process; later calls do nothing). Returns the slot.
int RegisterSmaPlugin();

}  // namespace recruit::sma
