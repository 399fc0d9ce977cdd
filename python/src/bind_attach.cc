// recruit.attach: `recruit attach` from Python (src/attach/attach.h). Returns the report the
// CLI's --report writes, as a dict; errors raise with the CLI's message: OSError when a file
// cannot be read or written (exit code 4 in the CLI), ValueError otherwise.
#include <Python.h>
#include <pybind11/stl.h>

#include <cmath>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "attach/attach.h"
#include "attach/report.h"
#include "bindings.h"
#include "common/result.h"
#include "convert.h"

namespace recruit::py_bind {
namespace {

[[noreturn]] void Raise(const Error& error) {
  if (error.code == ErrorCode::kIo) {
    PyErr_SetString(PyExc_OSError, error.message.c_str());
    throw py::error_already_set();
  }
  Fail(error.message);
}

// A path (str or os.PathLike); None -> "".
std::string PathArg(const py::object& o) {
  if (o.is_none()) return "";
  return py::module_::import("os").attr("fspath")(o).cast<std::string>();
}

// A comma-separated string (as the CLI option) or a sequence of names; None -> {}.
std::vector<std::string> NameList(const py::object& o, const std::string& what) {
  std::vector<std::string> out;
  if (o.is_none()) return out;
  if (py::isinstance<py::str>(o)) {
    std::stringstream in(o.cast<std::string>());
    for (std::string item; std::getline(in, item, ',');) {
      if (!item.empty()) out.push_back(item);
    }
    return out;
  }
  try {
    out = o.cast<std::vector<std::string>>();
  } catch (const py::cast_error&) {
    Fail(what + ": must be a string (comma-separated names) or a sequence of strings");
  }
  return out;
}

py::object Attach(const py::object& model, const py::object& muscles, const py::object& output,
                  const py::object& task, const py::object& report, bool size_only,
                  const py::object& force, bool lengthrange_from_joints, const py::object& lock,
                  double max_time_constant, double stroke_use, int units_per_holding_force,
                  double damping_ratio) {
  attach::AttachOptions o;
  o.model = PathArg(model);
  o.muscles = NameList(muscles, "muscles");
  o.output = PathArg(output);
  o.task = PathArg(task);
  o.report = PathArg(report);
  o.size_only = size_only;
  if (!force.is_none()) {
    try {
      o.force = force.cast<double>();
    } catch (const py::cast_error&) {
      Fail("force: must be a number (N) or None");
    }
    // The CLI's --force check (src/cli/attach_command.cc).
    if (!std::isfinite(o.force) || o.force <= 0 || o.force > 1e7) {
      Fail("force: value '" + py::str(force).cast<std::string>() +
           "' not allowed: must be a force in N (0 < force <= 1e7)");
    }
  }
  // The CLI's checks of the sizing options (src/cli/attach_command.cc).
  if (!(max_time_constant > 0 && max_time_constant <= 1e3)) {
    Fail("max_time_constant: value " + std::to_string(max_time_constant) +
         " not allowed: must be seconds (0 < s <= 1000)");
  }
  if (!(stroke_use >= 0.2 && stroke_use <= 0.95)) {
    Fail("stroke_use: value " + std::to_string(stroke_use) +
         " not allowed: must be a fraction in 0.2..0.95");
  }
  if (units_per_holding_force < 0 || units_per_holding_force > 1000) {
    Fail("units_per_holding_force: value " + std::to_string(units_per_holding_force) +
         " not allowed: must be in 0..1000");
  }
  if (!(damping_ratio >= 0 && damping_ratio <= 10)) {
    Fail("damping_ratio: value " + std::to_string(damping_ratio) +
         " not allowed: must be a ratio in 0..10");
  }
  o.limits.damping_ratio = damping_ratio;
  o.limits.max_time_constant = max_time_constant;
  o.limits.stroke_use = stroke_use;
  o.limits.units_per_holding_force = units_per_holding_force;
  o.lengthrange_from_joints = lengthrange_from_joints;
  o.lock = NameList(lock, "lock");
  std::optional<Result<attach::AttachReport>> r;
  {
    py::gil_scoped_release release;
    r.emplace(attach::Attach(o));
  }
  if (!r->ok()) Raise(r->failure());
  return py::module_::import("json").attr("loads")(attach::ReportJson(**r).dump());
}

}  // namespace

void BindAttach(py::module_& mod) {
  mod.def("attach", &Attach, py::arg("model"), py::arg("muscles"), py::arg("output") = py::none(),
          py::arg("task") = py::none(), py::arg("report") = py::none(),
          py::arg("size_only") = false, py::arg("force") = py::none(),
          py::arg("lengthrange_from_joints") = false, py::arg("lock") = py::none(),
          py::arg("max_time_constant") = attach::SizingLimits{}.max_time_constant,
          py::arg("stroke_use") = attach::SizingLimits{}.stroke_use,
          py::arg("units_per_holding_force") = attach::SizingLimits{}.units_per_holding_force,
          py::arg("damping_ratio") = attach::SizingLimits{}.damping_ratio,
          R"doc(Turns a MuJoCo model's muscles into sized recruit.sma bundles, as `recruit attach`.

model: the input MJCF. muscles: actuator names (a list, or one comma-separated string) or
"all" (every muscle on a tendon). output: the model to write (required unless size_only).
task: also write a starter task (JSON). report: also write the report (JSON). size_only: design
only, write nothing but the report. force: peak force of every bundle (N) instead of each
muscle's F0. lengthrange_from_joints: set the lengthrange of other muscles whose MuJoCo
computation fails from the joint ranges. lock: joints held at their reference value in the written
model (a joint equality each) and not driven by the starter task; the muscles kept beside the
bundles then get the lengthrange MuJoCo computes on the free limb, written explicitly.
max_time_constant, stroke_use, units_per_holding_force, damping_ratio: the sizing options of the
same names
(`recruit attach --help`, docs/sma-units.md "Sizing a bundle").

Returns the report as a dict (what `--report` writes: model, output, task, changes, warnings,
lengthranges_from_joints, lengthranges_without_locks, joints, holdable, bundles). Raises ValueError for bad input and OSError when a file
cannot be read or written, with the CLI's message; nothing is written on error.
docs/howto-own-model.md has the guide. The GIL is released meanwhile.)doc");
}

}  // namespace recruit::py_bind
