// recruit.Controller (one bundle's broadcast recruitment controller) and expectation_law.
#include <pybind11/stl.h>

#include <cmath>

#include "bindings.h"
#include "control/broadcast.h"
#include "control/recruitment_controller.h"
#include "convert.h"

namespace recruit::py_bind {
namespace {

using control::RecruitmentController;

control::ControllerParams Params(int n, double f, double dT, double lambda) {
  control::ControllerParams p;
  p.num_units = n;
  p.unit_force = f;
  p.dT = dT;
  p.lambda = lambda;
  Check(p.Validate());
  return p;
}

RecruitmentController MakeController(int num_units, double unit_force, double dT, double lambda,
                                     const std::string& estimator, const std::string& covariance,
                                     const std::string& model_file, int num_states,
                                     double force_noise_std) {
  return Take(RecruitmentController::Create(
      Params(num_units, unit_force, dT, lambda),
      Take(control::EstimatorSpec::Parse(estimator, covariance, model_file, num_states,
                                         force_noise_std))));
}

}  // namespace

void BindControl(py::module_& mod) {
  mod.def(
      "expectation_law",
      [](double target_on, double estimated_on, double num_units, double lambda) {
        const auto b = control::ExpectationLaw(target_on, estimated_on, num_units, lambda);
        return py::make_tuple(b.p_on, b.p_off);
      },
      py::arg("target_on"), py::arg("estimated_on"), py::arg("num_units"), py::arg("lam"),
      "The expectation law -> (p_on, p_off).");

  using C = RecruitmentController;
  py::class_<C>(mod, "Controller")
      .def(py::init(&MakeController), py::arg("num_units"), py::arg("unit_force"), py::arg("dT"),
           py::arg("lam") = 0.2, py::arg("estimator") = "kalman-augmented",
           py::arg("covariance") = "extended", py::arg("model_file") = "",
           py::arg("num_states") = 20, py::arg("force_noise_std") = 0.0)
      .def(
          "step",
          [](C& c, double reference, double measured) {
            if (!std::isfinite(reference)) Fail("step: reference force must be finite");
            if (!std::isfinite(measured)) Fail("step: measured force must be finite");
            const auto b = c.Step(reference, measured);
            return py::make_tuple(b.p_on, b.p_off);
          },
          py::arg("reference_force"), py::arg("measured_force"),
          "Once per dT: observe the force, apply the law, predict -> (p_on, p_off).")
      .def("reset", &C::Reset, "Back to all units off.")
      .def_property_readonly("target_on", &C::target_on, "Units the law aims at.")
      .def_property_readonly("estimated_on", &C::estimated_on, "Estimated on-count.")
      .def_property_readonly("estimated_on_variance", &C::estimated_on_variance,
                             "Variance of estimated_on (NaN: none).")
      .def_property_readonly(
          "state_estimate", [](C& c) { return FromVector(c.estimator().StateEstimate()); },
          "The estimator's state (counts per state).")
      .def_property_readonly(
          "state_names", [](C& c) { return c.estimator().StateNames(); }, "Its state names.")
      .def_property_readonly(
          "num_units", [](C& c) { return c.params().num_units; }, "N.")
      .def_property_readonly(
          "unit_force", [](C& c) { return c.params().unit_force; }, "N per unit on.")
      .def_property_readonly(
          "dT", [](C& c) { return c.params().dT; }, "Sampling period, s.")
      .def_property_readonly(
          "lam", [](C& c) { return c.params().lambda; }, "The law's gain.");
}

}  // namespace recruit::py_bind
