// _recruit: the pybind11 module behind the `recruit` Python package (docs/python.md). Thin
// wrappers over the C++ API; every Result error becomes a ValueError carrying the C++ message,
// and every input is checked here before it reaches code that assumes it valid (no crash on
// bad input). The Python layer (recruit/__init__.py) registers the plugin and adds docs.
#include <dlfcn.h>
#include <mujoco/mujoco.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <Eigen/Dense>
#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "control/broadcast.h"
#include "control/recruitment_controller.h"
#include "estimation/count_filter.h"
#include "estimation/filter_log.h"
#include "estimation/filter_model.h"
#include "estimation/population_kalman_filter.h"
#include "plugin/sma_host.h"
#include "sim/run_task.h"
#include "sim/task.h"

namespace py = pybind11;

namespace {

using recruit::CovarianceMode;
using recruit::FilterModel;
using recruit::PopulationKalmanFilter;
using recruit::sma::SmaHost;

[[noreturn]] void Fail(const std::string& message) { throw py::value_error(message); }

template <class T>
T Take(recruit::Result<T>&& r) {
  if (!r.ok()) Fail(r.error());
  return std::move(r).value();
}

void Check(const recruit::Status& s) {
  if (!s.ok()) Fail(s.error());
}

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

DoubleArray AsArray(const py::object& obj, const std::string& name) {
  DoubleArray a = DoubleArray::ensure(obj);
  if (!a) Fail(name + ": must be an array of numbers");
  return a;
}

// A 2-D array (a 1-D one of length 1 or a scalar reads as 1 x 1 when allowed).
Eigen::MatrixXd ToMatrix(const py::object& obj, const std::string& name) {
  DoubleArray a = AsArray(obj, name);
  if (a.ndim() == 0) {
    Eigen::MatrixXd M(1, 1);
    M(0, 0) = *a.data();
    return M;
  }
  if (a.ndim() != 2) {
    Fail(name + ": must be a 2-D array, got " + std::to_string(a.ndim()) + " dimensions");
  }
  Eigen::MatrixXd M(a.shape(0), a.shape(1));
  auto v = a.unchecked<2>();
  for (py::ssize_t i = 0; i < a.shape(0); ++i) {
    for (py::ssize_t j = 0; j < a.shape(1); ++j) M(i, j) = v(i, j);
  }
  return M;
}

Eigen::VectorXd ToVector(const py::object& obj, const std::string& name) {
  DoubleArray a = AsArray(obj, name);
  if (a.ndim() == 0) return Eigen::VectorXd::Constant(1, *a.data());
  if (a.ndim() != 1) {
    Fail(name + ": must be a 1-D array, got " + std::to_string(a.ndim()) + " dimensions");
  }
  return Eigen::Map<const Eigen::VectorXd>(a.data(), a.shape(0));
}

py::array_t<double> FromMatrix(const Eigen::MatrixXd& M) {
  py::array_t<double> out({M.rows(), M.cols()});
  auto v = out.mutable_unchecked<2>();
  for (Eigen::Index i = 0; i < M.rows(); ++i) {
    for (Eigen::Index j = 0; j < M.cols(); ++j) v(i, j) = M(i, j);
  }
  return out;
}

py::array_t<double> FromVector(const Eigen::VectorXd& x) {
  py::array_t<double> out(x.size());
  std::copy(x.data(), x.data() + x.size(), out.mutable_data());
  return out;
}

std::string TransitionName(recruit::TransitionSource t) {
  switch (t) {
    case recruit::TransitionSource::kBroadcast:
      return "broadcast";
    case recruit::TransitionSource::kExplicit:
      return "explicit";
    case recruit::TransitionSource::kConstant:
      return "constant";
  }
  return "?";
}

// ---------------------------------------------------------------------------------------------
// Filter models.

// A model built from arrays (the plain linear case and user models without a JSON file).
FilterModel LinearModel(const py::object& H, const py::object& R, int64_t N, const py::object& x0,
                        const py::object& P0, const py::object& A, const py::object& G,
                        const py::object& Qw, const py::object& state_names) {
  FilterModel f;
  f.N = N;
  f.H = ToMatrix(H, "H");
  f.R = ToMatrix(R, "R");
  const Eigen::Index m = f.H.cols();
  if (state_names.is_none()) {
    for (Eigen::Index i = 0; i < m; ++i) f.state_names.push_back("s" + std::to_string(i));
  } else {
    f.state_names = state_names.cast<std::vector<std::string>>();
  }
  if (A.is_none()) {
    f.transition = recruit::TransitionSource::kExplicit;
  } else {
    f.transition = recruit::TransitionSource::kConstant;
    f.A = ToMatrix(A, "A");
  }
  if (!G.is_none()) {
    f.G = ToMatrix(G, "G");
    f.Qw = Qw.is_none() ? Eigen::MatrixXd::Identity(f.G.cols(), f.G.cols()) : ToMatrix(Qw, "Qw");
  } else if (!Qw.is_none()) {
    Fail("Qw: given without G (pass G, the m x q process noise input)");
  }
  if (x0.is_none()) {
    f.x0 = Eigen::VectorXd::Zero(m);
    if (m > 0) f.x0(0) = static_cast<double>(N);
  } else {
    f.x0 = ToVector(x0, "x0");
  }
  f.P0 = P0.is_none() ? Eigen::MatrixXd::Zero(m, m) : ToMatrix(P0, "P0");
  Check(f.Validate("filter model"));
  return f;
}

// ---------------------------------------------------------------------------------------------
// The population Kalman filter (dynamic size).

class PyKalmanFilter {
 public:
  PyKalmanFilter(const FilterModel& model, const std::string& mode, const py::object& x0,
                 const py::object& P0)
      : model_(model),
        f_(Take(PopulationKalmanFilter::Create(model, Take(recruit::ParseCovarianceMode(mode)),
                                               x0.is_none() ? model.x0 : ToVector(x0, "x0"),
                                               P0.is_none() ? model.P0 : ToMatrix(P0, "P0")))) {}

  void Predict(const py::object& A) { Check(f_.PredictChecked(ToMatrix(A, "A"))); }

  void PredictBroadcast(double p_on, double p_off) {
    if (!f_.has_broadcast()) {
      Fail("predict_broadcast: the filter model's transition is '" +
           TransitionName(model_.transition) + "', not 'broadcast' (use predict(A))");
    }
    Check(recruit::BroadcastTransitionModel::ValidateInputs(p_on, p_off, "predict_broadcast"));
    f_.PredictBroadcast(p_on, p_off);
  }

  // Missing sample: None or all entries NaN (returns false, nothing changes).
  bool Update(const py::object& y) {
    if (y.is_none()) return false;
    const Eigen::VectorXd v = ToVector(y, "y");
    if (v.size() > 0 && v.array().isNaN().all()) return false;
    if (v.array().isNaN().any()) {
      Fail("y: some entries are NaN and some are not; a missing sample is all-NaN (or None)");
    }
    Check(f_.UpdateChecked(v));
    return true;
  }

  // The offline run (docs/formats/filter.md): for k = 0..T-1, predict with input k-1 (k > 0),
  // update with y[k] unless it is missing; the estimates and variances of every step.
  py::tuple Run(const py::object& ys, const py::object& p_on, const py::object& p_off,
                const py::object& As) {
    const Eigen::MatrixXd Y = ToMatrix(ys, "ys");
    const Eigen::Index T = Y.rows();
    const int m = f_.num_states();
    if (Y.cols() != f_.num_outputs()) {
      Fail("ys: must be T x " + std::to_string(f_.num_outputs()) +
           " (one column per output), got " + std::to_string(Y.rows()) + " x " +
           std::to_string(Y.cols()));
    }
    Eigen::VectorXd pon, poff;
    std::vector<Eigen::MatrixXd> Ak;
    const bool broadcast = !p_on.is_none() || !p_off.is_none();
    if (broadcast && !As.is_none()) Fail("run: pass either p_on and p_off or A, not both");
    if (broadcast) {
      if (!f_.has_broadcast()) Fail("run: p_on/p_off need a broadcast filter model");
      if (p_on.is_none() || p_off.is_none()) Fail("run: pass both p_on and p_off");
      pon = ToVector(p_on, "p_on");
      poff = ToVector(p_off, "p_off");
      if (pon.size() < T - 1 || poff.size() < T - 1) {
        Fail("run: p_on and p_off need at least T - 1 = " + std::to_string(T - 1) + " entries");
      }
      for (Eigen::Index k = 0; k + 1 < T; ++k) {
        Check(recruit::BroadcastTransitionModel::ValidateInputs(pon(k), poff(k),
                                                                "run: step " + std::to_string(k)));
      }
    } else if (!As.is_none()) {
      DoubleArray a = AsArray(As, "A");
      if (a.ndim() == 2) {
        Ak.push_back(ToMatrix(As, "A"));
      } else if (a.ndim() == 3 && a.shape(0) >= T - 1) {
        auto v = a.unchecked<3>();
        for (py::ssize_t k = 0; k < a.shape(0); ++k) {
          Eigen::MatrixXd M(a.shape(1), a.shape(2));
          for (py::ssize_t i = 0; i < a.shape(1); ++i)
            for (py::ssize_t j = 0; j < a.shape(2); ++j) M(i, j) = v(k, i, j);
          Ak.push_back(std::move(M));
        }
      } else {
        Fail("run: A must be m x m (constant) or (T - 1) x m x m");
      }
      for (size_t k = 0; k < Ak.size(); ++k) {
        Check(recruit::ValidateColumnStochastic(Ak[k], recruit::kStochasticTolerance, m,
                                                "run: A[" + std::to_string(k) + "]"));
      }
    } else if (model_.transition == recruit::TransitionSource::kConstant) {
      Ak.push_back(model_.A);
    } else if (T > 1) {
      Fail("run: this model's transition is '" + TransitionName(model_.transition) +
           "': pass p_on and p_off or A");
    }
    for (Eigen::Index k = 0; k < T; ++k) {
      const auto row = Y.row(k).array();
      if (row.isNaN().any() && !row.isNaN().all()) {
        Fail("ys: row " + std::to_string(k) + " is partly NaN; a missing sample is all-NaN");
      }
      if (!row.isNaN().all() && !row.allFinite()) {
        Fail("ys: row " + std::to_string(k) + " has an infinite entry");
      }
    }
    Eigen::MatrixXd X(T, m), V(T, m);
    {
      py::gil_scoped_release release;
      for (Eigen::Index k = 0; k < T; ++k) {
        if (k > 0) {
          if (broadcast) {
            f_.PredictBroadcast(pon(k - 1), poff(k - 1));
          } else {
            f_.Predict(Ak.size() == 1 ? Ak[0] : Ak[k - 1]);
          }
        }
        if (!Y.row(k).array().isNaN().all()) f_.Update(Y.row(k).transpose());
        X.row(k) = f_.estimate().transpose();
        V.row(k) = f_.covariance().diagonal().transpose();
      }
    }
    return py::make_tuple(FromMatrix(X), FromMatrix(V));
  }

  void Reset(const py::object& x0, const py::object& P0) {
    // Re-create to validate (sizes, sum N, PSD), keeping the mode.
    f_ = Take(PopulationKalmanFilter::Create(model_, f_.mode(),
                                             x0.is_none() ? model_.x0 : ToVector(x0, "x0"),
                                             P0.is_none() ? model_.P0 : ToMatrix(P0, "P0")));
  }

  const PopulationKalmanFilter& filter() const { return f_; }
  const FilterModel& model() const { return model_; }

 private:
  FilterModel model_;
  PopulationKalmanFilter f_;
};

// ---------------------------------------------------------------------------------------------
// Bundles on a user's mujoco.MjModel / MjData.

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

  int num_bundles() const { return host_->num_bundles(); }
  std::vector<std::string> names() const {
    std::vector<std::string> n;
    for (int b = 0; b < host_->num_bundles(); ++b) n.push_back(host_->bundle_name(b));
    return n;
  }
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

// ---------------------------------------------------------------------------------------------
// The recruitment controller.

class PyController {
 public:
  PyController(int num_units, double unit_force, double dT, double lambda,
               const std::string& estimator, const std::string& covariance,
               const std::string& model_file, int num_states, double force_noise_std)
      : c_(Take(recruit::control::RecruitmentController::Create(
            Params(num_units, unit_force, dT, lambda),
            Take(recruit::control::EstimatorSpec::Parse(estimator, covariance, model_file,
                                                        num_states, force_noise_std))))) {}

  py::tuple Step(double reference, double measured) {
    if (!std::isfinite(reference)) Fail("step: reference force must be finite");
    if (!std::isfinite(measured)) Fail("step: measured force must be finite");
    const auto b = c_.Step(reference, measured);
    return py::make_tuple(b.p_on, b.p_off);
  }
  recruit::control::RecruitmentController& c() { return c_; }

 private:
  static recruit::control::ControllerParams Params(int n, double f, double dT, double lambda) {
    recruit::control::ControllerParams p;
    p.num_units = n;
    p.unit_force = f;
    p.dT = dT;
    p.lambda = lambda;
    Check(p.Validate());
    return p;
  }
  recruit::control::RecruitmentController c_;
};

std::string LibraryOf(const void* symbol) {
  Dl_info info;
  if (dladdr(symbol, &info) == 0 || info.dli_fname == nullptr) return "";
  return info.dli_fname;
}

}  // namespace

PYBIND11_MODULE(_recruit, mod) {
  mod.doc() = "Recruit's C++ core (see the recruit package for documentation).";

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

  // Filter models.
  py::class_<FilterModel>(mod, "FilterModel")
      .def_static(
          "load", [](const std::string& path) { return Take(FilterModel::FromJson(path)); },
          py::arg("path"))
      .def_static(
          "two_state",
          [](int64_t N, double dt, double unit_force, double noise_std) {
            FilterModel f = FilterModel::TwoState(N, dt, unit_force, noise_std);
            Check(f.Validate("two_state"));
            return f;
          },
          py::arg("N"), py::arg("dt"), py::arg("unit_force"), py::arg("noise_std"))
      .def_static("linear", &LinearModel, py::arg("H"), py::arg("R"), py::arg("N"),
                  py::arg("x0") = py::none(), py::arg("P0") = py::none(), py::arg("A") = py::none(),
                  py::arg("G") = py::none(), py::arg("Qw") = py::none(),
                  py::arg("state_names") = py::none())
      .def("save", [](const FilterModel& f, const std::string& path) { Check(f.Save(path)); })
      .def("with_population",
           [](const FilterModel& f, int64_t N) {
             if (N < 1) Fail("with_population: N must be >= 1, got " + std::to_string(N));
             return f.WithPopulation(N);
           })
      .def("broadcast_matrix",
           [](const FilterModel& f, double p_on, double p_off) {
             if (f.transition != recruit::TransitionSource::kBroadcast) {
               Fail("broadcast_matrix: the model's transition is '" + TransitionName(f.transition) +
                    "'");
             }
             Check(recruit::BroadcastTransitionModel::ValidateInputs(p_on, p_off,
                                                                     "broadcast_matrix"));
             return FromMatrix(f.broadcast.Matrix(p_on, p_off));
           })
      .def_property_readonly("state_names", [](const FilterModel& f) { return f.state_names; })
      .def_property_readonly("is_on",
                             [](const FilterModel& f) {
                               return std::vector<bool>(f.broadcast.is_on.begin(),
                                                        f.broadcast.is_on.end());
                             })
      .def_property_readonly("N", [](const FilterModel& f) { return f.N; })
      .def_property_readonly("H", [](const FilterModel& f) { return FromMatrix(f.H); })
      .def_property_readonly("R", [](const FilterModel& f) { return FromMatrix(f.R); })
      .def_property_readonly("G", [](const FilterModel& f) { return FromMatrix(f.G); })
      .def_property_readonly("Qw", [](const FilterModel& f) { return FromMatrix(f.Qw); })
      .def_property_readonly("process_noise",
                             [](const FilterModel& f) { return FromMatrix(f.ProcessNoise()); })
      .def_property_readonly("A", [](const FilterModel& f) { return FromMatrix(f.A); })
      .def_property_readonly("x0", [](const FilterModel& f) { return FromVector(f.x0); })
      .def_property_readonly("P0", [](const FilterModel& f) { return FromMatrix(f.P0); })
      .def_property_readonly("dt", [](const FilterModel& f) { return f.broadcast.dt; })
      .def_property_readonly("transition",
                             [](const FilterModel& f) { return TransitionName(f.transition); })
      .def_property_readonly("num_states", &FilterModel::num_states)
      .def_property_readonly("num_outputs", &FilterModel::num_outputs)
      .def("__repr__", [](const FilterModel& f) {
        return "<recruit.FilterModel m=" + std::to_string(f.num_states()) +
               " r=" + std::to_string(f.num_outputs()) + " N=" + std::to_string(f.N) +
               " transition=" + TransitionName(f.transition) + ">";
      });

  py::class_<PyKalmanFilter>(mod, "KalmanFilter")
      .def(py::init<const FilterModel&, const std::string&, const py::object&, const py::object&>(),
           py::arg("model"), py::arg("mode") = "extended", py::arg("x0") = py::none(),
           py::arg("P0") = py::none())
      .def("predict", &PyKalmanFilter::Predict, py::arg("A"))
      .def("predict_broadcast", &PyKalmanFilter::PredictBroadcast, py::arg("p_on"),
           py::arg("p_off"))
      .def("update", &PyKalmanFilter::Update, py::arg("y"))
      .def("run", &PyKalmanFilter::Run, py::arg("ys"), py::arg("p_on") = py::none(),
           py::arg("p_off") = py::none(), py::arg("A") = py::none())
      .def("reset", &PyKalmanFilter::Reset, py::arg("x0") = py::none(), py::arg("P0") = py::none())
      .def_property_readonly(
          "x", [](const PyKalmanFilter& k) { return FromVector(k.filter().estimate()); })
      .def_property_readonly(
          "P", [](const PyKalmanFilter& k) { return FromMatrix(k.filter().covariance()); })
      .def_property_readonly(
          "innovation", [](const PyKalmanFilter& k) { return FromVector(k.filter().innovation()); })
      .def_property_readonly("K",
                             [](const PyKalmanFilter& k) { return FromMatrix(k.filter().gain()); })
      .def_property_readonly(
          "mode", [](const PyKalmanFilter& k) { return std::string(ToString(k.filter().mode())); })
      .def_property_readonly("N", [](const PyKalmanFilter& k) { return k.filter().population(); })
      .def_property_readonly("num_states",
                             [](const PyKalmanFilter& k) { return k.filter().num_states(); })
      .def_property_readonly("num_outputs",
                             [](const PyKalmanFilter& k) { return k.filter().num_outputs(); })
      .def_property_readonly("model", [](const PyKalmanFilter& k) { return k.model(); });

  mod.def(
      "filter_log",
      [](const std::string& model_path, const std::string& log_path, const std::string& estimator,
         int particles, uint64_t seed) {
        FilterModel model = Take(FilterModel::FromJson(model_path));
        recruit::CountFilterOptions opt;
        opt.estimator = estimator;
        opt.particles = particles;
        opt.seed = seed;
        auto filter = Take(recruit::MakeCountFilter(model, opt));
        auto log = Take(recruit::FilterLogReader::OpenFile(log_path, model));
        std::ostringstream out;
        {
          py::gil_scoped_release release;
          Check(recruit::RunFilterStream(model, *log, *filter, out));
        }
        return out.str();
      },
      py::arg("model_path"), py::arg("log_path"), py::arg("estimator") = "extended",
      py::arg("particles") = 1000, py::arg("seed") = 1);

  // Bundles.
  py::class_<PyBundles>(mod, "Bundles")
      .def(py::init<py::object>(), py::arg("model"))
      .def_property_readonly("num_bundles", &PyBundles::num_bundles)
      .def_property_readonly("names", &PyBundles::names)
      .def_property_readonly("model", &PyBundles::model)
      .def("index", &PyBundles::Index, py::arg("bundle"))
      .def("num_units",
           [](const PyBundles& s, const py::object& b) { return s.host().num_units(s.Index(b)); })
      .def("actuator_id",
           [](const PyBundles& s, const py::object& b) { return s.host().actuator_id(s.Index(b)); })
      .def("tendon_id",
           [](const PyBundles& s, const py::object& b) { return s.host().tendon_id(s.Index(b)); })
      .def("settled_unit_force",
           [](const PyBundles& s, const py::object& b) {
             return s.host().SettledUnitForce(s.Index(b));
           })
      .def(
          "reset",
          [](const PyBundles& s, const py::object& data, uint64_t seed) {
            s.host().Reset(s.Data(data), seed);
          },
          py::arg("data"), py::arg("seed"))
      .def(
          "broadcast",
          [](const PyBundles& s, const py::object& data, const py::object& b, double p_on,
             double p_off) {
            const int i = s.Index(b);
            Check(recruit::BroadcastTransitionModel::ValidateInputs(p_on, p_off, "broadcast"));
            Check(s.host().Broadcast(s.Data(data), i, p_on, p_off));
          },
          py::arg("data"), py::arg("bundle"), py::arg("p_on"), py::arg("p_off"))
      .def(
          "on_count",
          [](const PyBundles& s, const py::object& data, const py::object& b) {
            const int i = s.Index(b);
            return s.host().OnCount(s.Data(data), i);
          },
          py::arg("data"), py::arg("bundle"))
      .def(
          "force",
          [](const PyBundles& s, const py::object& data, const py::object& b) {
            const int i = s.Index(b);
            return s.host().Force(s.Data(data), i);
          },
          py::arg("data"), py::arg("bundle"))
      .def(
          "mean_temperature",
          [](const PyBundles& s, const py::object& data, const py::object& b) {
            const int i = s.Index(b);
            return s.host().MeanTemperature(s.Data(data), i);
          },
          py::arg("data"), py::arg("bundle"))
      .def(
          "heat",
          [](const PyBundles& s, const py::object& data, const py::object& b) {
            const int i = s.Index(b);
            return s.host().Heat(s.Data(data), i);
          },
          py::arg("data"), py::arg("bundle"))
      .def(
          "unit_temperatures",
          [](const PyBundles& s, const py::object& data, const py::object& b) {
            const int i = s.Index(b);
            const mjData* d = s.Data(data);
            const int n = s.host().num_units(i);
            py::array_t<double> out(n);
            double* o = out.mutable_data();
            for (int u = 0; u < n; ++u) o[u] = s.host().UnitTemperature(d, i, u);
            return out;
          },
          py::arg("data"), py::arg("bundle"))
      .def(
          "unit_xi",
          [](const PyBundles& s, const py::object& data, const py::object& b) {
            const int i = s.Index(b);
            const mjData* d = s.Data(data);
            const int n = s.host().num_units(i);
            py::array_t<double> out(n);
            double* o = out.mutable_data();
            for (int u = 0; u < n; ++u) o[u] = s.host().UnitXi(d, i, u);
            return out;
          },
          py::arg("data"), py::arg("bundle"))
      .def(
          "units_on",
          [](const PyBundles& s, const py::object& data, const py::object& b) {
            const int i = s.Index(b);
            const mjData* d = s.Data(data);
            const int n = s.host().num_units(i);
            py::array_t<bool> out(n);
            bool* o = out.mutable_data();
            for (int u = 0; u < n; ++u) o[u] = s.host().UnitOn(d, i, u);
            return out;
          },
          py::arg("data"), py::arg("bundle"));

  // Controller.
  mod.def(
      "expectation_law",
      [](double target_on, double estimated_on, double num_units, double lambda) {
        const auto b = recruit::control::ExpectationLaw(target_on, estimated_on, num_units, lambda);
        return py::make_tuple(b.p_on, b.p_off);
      },
      py::arg("target_on"), py::arg("estimated_on"), py::arg("num_units"), py::arg("lam"));

  py::class_<PyController>(mod, "Controller")
      .def(py::init<int, double, double, double, const std::string&, const std::string&,
                    const std::string&, int, double>(),
           py::arg("num_units"), py::arg("unit_force"), py::arg("dT"), py::arg("lam") = 0.2,
           py::arg("estimator") = "kalman-augmented", py::arg("covariance") = "extended",
           py::arg("model_file") = "", py::arg("num_states") = 20, py::arg("force_noise_std") = 0.0)
      .def("step", &PyController::Step, py::arg("reference_force"), py::arg("measured_force"))
      .def("reset", [](PyController& c) { c.c().Reset(); })
      .def_property_readonly("target_on", [](PyController& c) { return c.c().target_on(); })
      .def_property_readonly("estimated_on", [](PyController& c) { return c.c().estimated_on(); })
      .def_property_readonly("estimated_on_variance",
                             [](PyController& c) { return c.c().estimated_on_variance(); })
      .def_property_readonly(
          "state_estimate",
          [](PyController& c) { return FromVector(c.c().estimator().StateEstimate()); })
      .def_property_readonly("state_names",
                             [](PyController& c) { return c.c().estimator().StateNames(); })
      .def_property_readonly("num_units", [](PyController& c) { return c.c().params().num_units; })
      .def_property_readonly("unit_force",
                             [](PyController& c) { return c.c().params().unit_force; })
      .def_property_readonly("dT", [](PyController& c) { return c.c().params().dT; })
      .def_property_readonly("lam", [](PyController& c) { return c.c().params().lambda; });

  // Runs.
  mod.def(
      "simulate_json",
      [](const std::string& task_path, const py::object& estimator, const py::object& filter_model,
         const py::object& dT, const py::object& lambda, const py::object& force_noise_std,
         const py::object& duration, uint64_t seed) {
        recruit::sim::Task task = Take(recruit::sim::Task::FromFile(task_path));
        recruit::sim::RunOptions opt;
        if (!estimator.is_none()) opt.estimator = estimator.cast<std::string>();
        if (!filter_model.is_none()) opt.filter_model = filter_model.cast<std::string>();
        if (!dT.is_none()) opt.dT = dT.cast<double>();
        if (!lambda.is_none()) opt.lambda = lambda.cast<double>();
        if (!force_noise_std.is_none()) opt.force_noise_std = force_noise_std.cast<double>();
        if (!duration.is_none()) opt.duration = duration.cast<double>();
        opt.seed = seed;
        std::string json;
        {
          py::gil_scoped_release release;
          auto r = recruit::sim::RunTask(task, opt);
          if (r.ok())
            json = r->ToJson().dump();
          else
            json = "\x01" + r.error();  // raised below, with the GIL held
        }
        if (!json.empty() && json[0] == '\x01') Fail(json.substr(1));
        return json;
      },
      py::arg("task_path"), py::arg("estimator") = py::none(), py::arg("filter_model") = py::none(),
      py::arg("dT") = py::none(), py::arg("lam") = py::none(),
      py::arg("force_noise_std") = py::none(), py::arg("duration") = py::none(),
      py::arg("seed") = 1);
}
