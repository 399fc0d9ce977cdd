// _recruit: the pybind11 module behind the `recruit` Python package (docs/python.md). Thin
// wrappers over the C++ API; every input is checked before it reaches code that assumes it
// valid (no crash on bad input). recruit/__init__.py registers the plugin and adds the
// Python-side helpers.
#include "bindings.h"
#include "common/data_path.h"
#include "common/mujoco_warnings.h"

PYBIND11_MODULE(_recruit, mod) {
  mod.doc() = "Recruit's C++ core (see the recruit package for documentation).";
  recruit::InstallMujocoWarnings();  // stderr, once each, no MUJOCO_LOG.TXT in the working folder
  recruit::py_bind::BindPlugin(mod);
  recruit::py_bind::BindFilter(mod);
  recruit::py_bind::BindControl(mod);
  recruit::py_bind::BindSim(mod);
  recruit::py_bind::BindAttach(mod);
  mod.def(
      "set_data_dir", &recruit::SetDataDir, pybind11::arg("folder"),
      "The folder holding the shipped models/ (common/data_path.h; RECRUIT_DATA_DIR overrides)");
}
