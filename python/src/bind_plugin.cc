// The plugin side: which libraries are loaded, and recruit.Bundles, the recruit.sma bundles of
// a user's mujoco.MjModel / MjData (the official bindings' objects, by address).
#include <dlfcn.h>
#include <mujoco/mujoco.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bindings.h"
#include "convert.h"
#include "estimation/broadcast_transition_model.h"
#include "plugin/sma_host.h"

namespace recruit::py_bind {
namespace {

using sma::SmaHost;

std::string LibraryOf(const void* symbol) {
  Dl_info info;
  if (dladdr(symbol, &info) == 0 || info.dli_fname == nullptr) return "";
  return info.dli_fname;
}

mjModel* ModelPointer(const py::object& model) {
  if (!py::hasattr(model, "_address")) Fail("model: must be a mujoco.MjModel");
  return reinterpret_cast<mjModel*>(model.attr("_address").cast<std::uintptr_t>());
}

class PyBundles {
 public:
  explicit PyBundles(py::object model) : model_obj_(std::move(model)) {
    m_ = ModelPointer(model_obj_);
    host_ = Take(SmaHost::Create(m_));
  }

  std::vector<std::string> names() const {
    std::vector<std::string> n;
    for (int b = 0; b < host_->num_bundles(); ++b) n.push_back(host_->bundle_name(b));
    return n;
  }
  // A bundle index from an index or an actuator name, checked.
  int Index(const py::object& b) const {
    if (py::isinstance<py::str>(b)) {
      const std::string name = b.cast<std::string>();
      const int i = host_->BundleIndex(name);
      if (i < 0) Fail("bundle: no recruit.sma actuator named '" + name.substr(0, 40) + "'");
      return i;
    }
    if (!py::isinstance<py::int_>(b)) Fail("bundle: must be an index or an actuator name");
    const long i = b.cast<long>();
    if (i < 0 || i >= host_->num_bundles()) {
      Fail("bundle: index " + std::to_string(i) + " out of range [0, " +
           std::to_string(host_->num_bundles()) + ")");
    }
    return static_cast<int>(i);
  }
  // The mjData of a mujoco.MjData made for this model.
  mjData* Data(const py::object& data) const {
    if (!py::hasattr(data, "_address") || !py::hasattr(data, "model")) {
      Fail("data: must be a mujoco.MjData");
    }
    const auto maddr = data.attr("model").attr("_address").cast<std::uintptr_t>();
    if (maddr != reinterpret_cast<std::uintptr_t>(m_)) {
      Fail("data: this MjData was made for another MjModel than the one of these Bundles");
    }
    return reinterpret_cast<mjData*>(data.attr("_address").cast<std::uintptr_t>());
  }

  const SmaHost& host() const { return *host_; }
  const py::object& model() const { return model_obj_; }

 private:
  py::object model_obj_;  // keeps the MjModel alive while the host points into it
  mjModel* m_ = nullptr;
  std::unique_ptr<SmaHost> host_;
};

using BundlesClass = py::class_<PyBundles>;

// bundles.name(bundle) -> host.fn(b): per-bundle constants.
template <class R>
void DefConstant(BundlesClass& c, const char* name, R (SmaHost::*fn)(int) const, const char* doc) {
  c.def(
      name, [fn](const PyBundles& s, const py::object& b) { return (s.host().*fn)(s.Index(b)); },
      py::arg("bundle"), doc);
}

// bundles.name(data, bundle) -> host.fn(d, b): per-bundle state.
template <class R>
void DefState(BundlesClass& c, const char* name, R (SmaHost::*fn)(const mjData*, int) const,
              const char* doc) {
  c.def(
      name,
      [fn](const PyBundles& s, const py::object& data, const py::object& b) {
        const int i = s.Index(b);
        return (s.host().*fn)(s.Data(data), i);
      },
      py::arg("data"), py::arg("bundle"), doc);
}

// bundles.name(data, bundle) -> ndarray of host.fn(d, b, u) over the units u.
template <class R>
void DefPerUnit(BundlesClass& c, const char* name, R (SmaHost::*fn)(const mjData*, int, int) const,
                const char* doc) {
  c.def(
      name,
      [fn](const PyBundles& s, const py::object& data, const py::object& b) {
        const int i = s.Index(b);
        const mjData* d = s.Data(data);
        const int n = s.host().num_units(i);
        py::array_t<R> out(n);
        R* o = out.mutable_data();
        for (int u = 0; u < n; ++u) o[u] = (s.host().*fn)(d, i, u);
        return out;
      },
      py::arg("data"), py::arg("bundle"), doc);
}

// The units grouped by identical state (the plugin's cohorts): count, on, temperature, xi.
py::dict Cohorts(const PyBundles& s, const py::object& data, const py::object& b) {
  const int i = s.Index(b);
  const mjData* d = s.Data(data);
  const SmaHost& h = s.host();
  std::map<int, int> first_unit, count;  // by cohort index
  for (int u = 0; u < h.num_units(i); ++u) {
    const int c = h.UnitCohort(d, i, u);
    first_unit.emplace(c, u);
    ++count[c];
  }
  const py::ssize_t k = static_cast<py::ssize_t>(count.size());
  py::array_t<int> n(k);
  py::array_t<bool> on(k);
  py::array_t<double> temp(k), xi(k);
  py::ssize_t j = 0;
  for (const auto& [c, u] : first_unit) {
    n.mutable_data()[j] = count[c];
    on.mutable_data()[j] = h.UnitOn(d, i, u);
    temp.mutable_data()[j] = h.UnitTemperature(d, i, u);
    xi.mutable_data()[j] = h.UnitXi(d, i, u);
    ++j;
  }
  py::dict out;
  out["count"] = n;
  out["on"] = on;
  out["temperature"] = temp;
  out["xi"] = xi;
  return out;
}

}  // namespace

void BindPlugin(py::module_& mod) {
  mod.def(
      "mujoco_version", [] { return std::string(mj_versionString()); },
      "Version of the libmujoco this module runs with.");
  mod.def(
      "mujoco_header_version", [] { return static_cast<int>(mjVERSION_HEADER); },
      "mjVERSION_HEADER of the MuJoCo headers this module was compiled against.");
  mod.def(
      "plugin_library", [] { return LibraryOf(reinterpret_cast<void*>(&SmaHost::Create)); },
      "Path of the librecruit_sma.so this module uses (the one that registered recruit.sma).");
  mod.def(
      "mujoco_library", [] { return LibraryOf(reinterpret_cast<void*>(&mj_step)); },
      "Path of the libmujoco this module uses.");

  BundlesClass c(mod, "Bundles");
  c.def(py::init<py::object>(), py::arg("model"))
      .def_property_readonly(
          "num_bundles", [](const PyBundles& s) { return s.host().num_bundles(); },
          "Number of recruit.sma actuators.")
      .def_property_readonly("names", &PyBundles::names, "Actuator names, in actuator order.")
      .def_property_readonly("model", &PyBundles::model, "The mujoco.MjModel.")
      .def("index", &PyBundles::Index, py::arg("bundle"), "Index of a bundle (index or name).")
      .def(
          "reset",
          [](const PyBundles& s, const py::object& data, uint64_t seed) {
            s.host().Reset(s.Data(data), seed);
          },
          py::arg("data"), py::arg("seed"),
          "Every unit off and cold; seeds each bundle's random stream from seed.")
      .def(
          "broadcast",
          [](const PyBundles& s, const py::object& data, const py::object& b, double p_on,
             double p_off) {
            const int i = s.Index(b);
            Check(estimation::BroadcastTransitionModel::ValidateInputs(p_on, p_off, "broadcast"));
            Check(s.host().Broadcast(s.Data(data), i, p_on, p_off));
          },
          py::arg("data"), py::arg("bundle"), py::arg("p_on"), py::arg("p_off"),
          "Each unit switches off->on with probability p_on, on->off with p_off.")
      .def(
          "state_counts",
          [](const PyBundles& s, const py::object& data, const py::object& b) {
            const int i = s.Index(b);
            const int on = s.host().OnCount(s.Data(data), i);
            py::array_t<int> out(2);
            out.mutable_data()[0] = s.host().num_units(i) - on;
            out.mutable_data()[1] = on;
            return out;
          },
          py::arg("data"), py::arg("bundle"),
          "True counts per state of the two-state model (FilterModel.two_state order: off, on).")
      .def("cohorts", &Cohorts, py::arg("data"), py::arg("bundle"),
           "The units grouped by identical state -> dict of arrays: count, on, temperature (C), "
           "xi (martensite fraction).");
  DefConstant(c, "num_units", &SmaHost::num_units, "Number of units of a bundle.");
  DefConstant(c, "actuator_id", &SmaHost::actuator_id, "MuJoCo actuator id of a bundle.");
  DefConstant(c, "tendon_id", &SmaHost::tendon_id, "MuJoCo tendon id a bundle pulls.");
  DefConstant(c, "settled_unit_force", &SmaHost::SettledUnitForce,
              "Steady tension (N) of one unit held on, at the model's rest length.");
  DefState(c, "on_count", &SmaHost::OnCount, "True number of units whose heater is on.");
  DefState(c, "force", &SmaHost::Force, "Tension (N) at the current tendon length.");
  DefState(c, "mean_temperature", &SmaHost::MeanTemperature, "Mean unit temperature (C).");
  DefState(c, "heat", &SmaHost::Heat, "0 at ambient .. 1 at the on-state steady temperature.");
  DefState(c, "num_cohorts", &SmaHost::NumCohorts, "Number of distinct unit states.");
  DefPerUnit(c, "unit_temperatures", &SmaHost::UnitTemperature, "Per-unit temperature (C).");
  DefPerUnit(c, "unit_xi", &SmaHost::UnitXi, "Per-unit martensite fraction.");
  DefPerUnit(c, "units_on", &SmaHost::UnitOn, "Per-unit heater state.");
}

}  // namespace recruit::py_bind
