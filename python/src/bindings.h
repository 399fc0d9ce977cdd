// The parts of the _recruit module, one per concept (module.cc assembles them).
#pragma once

#include <pybind11/pybind11.h>

namespace recruit::py_bind {

void BindFilter(pybind11::module_& mod);   // bind_filter.cc: filter models and filters
void BindPlugin(pybind11::module_& mod);   // bind_plugin.cc: libraries, Bundles
void BindControl(pybind11::module_& mod);  // bind_control.cc: Controller, expectation_law
void BindSim(pybind11::module_& mod);      // bind_sim.cc: simulate, sweep, aggregate
void BindAttach(pybind11::module_& mod);   // bind_attach.cc: attach (recruit attach)

}  // namespace recruit::py_bind
