// _recruit: the pybind11 module behind the `recruit` Python package (docs/python.md). Thin
// wrappers over the C++ API; every input is checked before it reaches code that assumes it
// valid (no crash on bad input). recruit/__init__.py registers the plugin and adds the
// Python-side helpers.
#include "bindings.h"

PYBIND11_MODULE(_recruit, mod) {
  mod.doc() = "Recruit's C++ core (see the recruit package for documentation).";
  recruit::py_bind::BindPlugin(mod);
  recruit::py_bind::BindFilter(mod);
  recruit::py_bind::BindControl(mod);
  recruit::py_bind::BindSim(mod);
  recruit::py_bind::BindAttach(mod);
}
