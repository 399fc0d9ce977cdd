// recruit.FilterModel, KalmanFilter, ExactFilter, ParticleFilter and filter_log.
#include <pybind11/stl.h>

#include <sstream>

#include "bindings.h"
#include "convert.h"
#include "estimation/count_filter.h"
#include "estimation/filter_log.h"
#include "filters.h"

namespace recruit::py_bind {
namespace {

// A model built from arrays (the plain linear case and user models without a JSON file).
estimation::FilterModel LinearModel(const py::object& H, const py::object& R, int64_t N,
                                    const py::object& x0, const py::object& P0, const py::object& A,
                                    const py::object& G, const py::object& Qw,
                                    const py::object& state_names) {
  estimation::FilterModel f;
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
    f.transition = estimation::TransitionSource::kExplicit;
  } else {
    f.transition = estimation::TransitionSource::kConstant;
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

std::string FilterLog(const std::string& model_path, const std::string& log_path,
                      const std::string& estimator, int particles, uint64_t seed) {
  estimation::FilterModel model = Take(estimation::FilterModel::FromJson(model_path));
  estimation::CountFilterOptions opt;
  opt.estimator = estimator;
  opt.particles = particles;
  opt.seed = seed;
  auto filter = Take(estimation::MakeCountFilter(model, opt));
  auto log = Take(estimation::FilterLogReader::OpenFile(log_path, model));
  std::ostringstream out;
  Status s = Status::Ok();
  {
    py::gil_scoped_release release;
    s = estimation::RunFilterStream(model, *log, *filter, out);
  }
  Check(s);
  return out.str();
}

}  // namespace

void BindFilter(py::module_& mod) {
  // The step and run methods every filter object shares, bound once on the base (they
  // dispatch to the C++ filter through PyFilter's virtual functions).
  py::class_<PyFilter>(mod, "_Filter", "Base of the filter objects (not constructible).")
      .def("predict", &PyFilter::Predict, py::arg("A"),
           "Time update with an m x m column-stochastic transition matrix A.")
      .def("predict_broadcast", &PyFilter::PredictBroadcast, py::arg("p_on"), py::arg("p_off"),
           "Time update with the model's broadcast transition A(p_on, p_off).")
      .def("update", &PyFilter::Update, py::arg("y"),
           "Measurement update with y (r entries). None or all-NaN is a missing sample: nothing "
           "changes and False is returned; otherwise True.")
      .def("run", &PyFilter::Run, py::arg("ys"), py::arg("p_on") = py::none(),
           py::arg("p_off") = py::none(), py::arg("A") = py::none(),
           "Runs a whole log -> (X, V), the T x m estimates and covariance diagonals. For k = "
           "0..T-1: predict with input k-1 (k > 0: p_on[k-1], p_off[k-1], or A / A[k-1], or the "
           "model's constant A), then update with ys[k] unless the row is all-NaN. The GIL is "
           "released meanwhile.")
      .def_property_readonly(
          "x", [](const PyFilter& f) { return FromVector(f.Mean()); },
          "The estimate, counts per state.")
      .def_property_readonly(
          "P", [](const PyFilter& f) { return FromMatrix(f.Covariance()); },
          "The covariance of the estimate (m x m).")
      .def_property_readonly(
          "model", [](const PyFilter& f) { return f.model(); }, "The FilterModel (a copy).")
      .def_property_readonly(
          "N", [](const PyFilter& f) { return f.model().N; }, "The population size.")
      .def_property_readonly(
          "num_states", [](const PyFilter& f) { return f.model().num_states(); }, "m.")
      .def_property_readonly(
          "num_outputs", [](const PyFilter& f) { return f.model().num_outputs(); }, "r.");

  py::class_<estimation::FilterModel>(mod, "FilterModel")
      .def_static(
          "load",
          [](const std::string& path) { return Take(estimation::FilterModel::FromJson(path)); },
          py::arg("path"), "Reads a filter model file (docs/formats/filter.md).")
      .def_static(
          "two_state",
          [](int64_t N, double dt, double unit_force, double noise_std) {
            estimation::FilterModel f =
                estimation::FilterModel::TwoState(N, dt, unit_force, noise_std);
            Check(f.Validate("two_state"));
            return f;
          },
          py::arg("N"), py::arg("dt"), py::arg("unit_force"), py::arg("noise_std"),
          "The off/on broadcast model of N units with a force sensor (y = unit_force n_on + v).")
      .def_static("linear", &LinearModel, py::arg("H"), py::arg("R"), py::arg("N"),
                  py::arg("x0") = py::none(), py::arg("P0") = py::none(), py::arg("A") = py::none(),
                  py::arg("G") = py::none(), py::arg("Qw") = py::none(),
                  py::arg("state_names") = py::none(),
                  "A model from arrays: y = H X + v, v ~ N(0, R); A given = constant transition, "
                  "else pass A at every predict; process noise G Qw G^T (zero column sums).")
      .def(
          "save",
          [](const estimation::FilterModel& f, const std::string& path) { Check(f.Save(path)); },
          py::arg("path"), "Writes the model as a filter model file.")
      .def(
          "with_population",
          [](const estimation::FilterModel& f, int64_t N) {
            if (N < 1) Fail("with_population: N must be >= 1, got " + std::to_string(N));
            return f.WithPopulation(N);
          },
          py::arg("N"), "The same model for N units (x0 and P0 scaled).")
      .def(
          "broadcast_matrix",
          [](const estimation::FilterModel& f, double p_on, double p_off) {
            if (f.transition != estimation::TransitionSource::kBroadcast) {
              Fail("broadcast_matrix: the model's transition is '" + TransitionName(f.transition) +
                   "'");
            }
            Check(estimation::BroadcastTransitionModel::ValidateInputs(p_on, p_off,
                                                                       "broadcast_matrix"));
            return FromMatrix(f.broadcast.Matrix(p_on, p_off));
          },
          py::arg("p_on"), py::arg("p_off"), "The dense m x m A(p_on, p_off).")
      .def_property_readonly(
          "state_names", [](const estimation::FilterModel& f) { return f.state_names; },
          "State names.")
      .def_property_readonly(
          "is_on",
          [](const estimation::FilterModel& f) {
            return std::vector<bool>(f.broadcast.is_on.begin(), f.broadcast.is_on.end());
          },
          "Per state: the heater is on (broadcast models).")
      .def_property_readonly(
          "N", [](const estimation::FilterModel& f) { return f.N; }, "Population size.")
      .def_property_readonly(
          "H", [](const estimation::FilterModel& f) { return FromMatrix(f.H); },
          "r x m output matrix.")
      .def_property_readonly(
          "R", [](const estimation::FilterModel& f) { return FromMatrix(f.R); },
          "r x r noise covariance.")
      .def_property_readonly(
          "G", [](const estimation::FilterModel& f) { return FromMatrix(f.G); },
          "m x q noise input.")
      .def_property_readonly(
          "Qw", [](const estimation::FilterModel& f) { return FromMatrix(f.Qw); },
          "q x q noise covariance.")
      .def_property_readonly(
          "process_noise",
          [](const estimation::FilterModel& f) { return FromMatrix(f.ProcessNoise()); },
          "G Qw G^T.")
      .def_property_readonly(
          "A", [](const estimation::FilterModel& f) { return FromMatrix(f.A); },
          "The constant transition (transition == 'constant').")
      .def_property_readonly(
          "x0", [](const estimation::FilterModel& f) { return FromVector(f.x0); },
          "Initial estimate.")
      .def_property_readonly(
          "P0", [](const estimation::FilterModel& f) { return FromMatrix(f.P0); },
          "Initial covariance.")
      .def_property_readonly(
          "dt", [](const estimation::FilterModel& f) { return f.broadcast.dt; },
          "Sampling period, s.")
      .def_property_readonly(
          "transition",
          [](const estimation::FilterModel& f) { return TransitionName(f.transition); },
          "'broadcast', 'explicit' or 'constant'.")
      .def_property_readonly("num_states", &estimation::FilterModel::num_states, "m.")
      .def_property_readonly("num_outputs", &estimation::FilterModel::num_outputs, "r.")
      .def("__repr__", [](const estimation::FilterModel& f) {
        return "<recruit.FilterModel m=" + std::to_string(f.num_states()) +
               " r=" + std::to_string(f.num_outputs()) + " N=" + std::to_string(f.N) +
               " transition=" + TransitionName(f.transition) + ">";
      });

  py::class_<PyKalmanFilter, PyFilter> kf(mod, "KalmanFilter");
  kf.def(py::init<const estimation::FilterModel&, const std::string&, const py::object&,
                  const py::object&, bool>(),
         py::arg("model"), py::arg("mode") = "extended", py::arg("x0") = py::none(),
         py::arg("P0") = py::none(), py::arg("fixed_size") = true)
      .def("reset", &PyKalmanFilter::Reset, py::arg("x0") = py::none(), py::arg("P0") = py::none(),
           "Back to a belief (default: the model's x0, P0), validated.")
      .def("set_output", &PyKalmanFilter::SetOutput, py::arg("H"), py::arg("R"),
           "Replaces the output model (H r x m, R r x r SPD) for the next updates.")
      .def_property_readonly(
          "innovation", [](const PyKalmanFilter& k) { return FromVector(k.core().innovation()); },
          "y - H x of the last update (r,).")
      .def_property_readonly(
          "K", [](const PyKalmanFilter& k) { return FromMatrix(k.core().gain()); },
          "The gain of the last update (m x r).")
      .def_property_readonly(
          "H", [](const PyKalmanFilter& k) { return FromMatrix(k.core().H()); },
          "The output matrix in use (r x m).")
      .def_property_readonly(
          "mode", [](const PyKalmanFilter& k) { return std::string(ToString(k.mode())); },
          "'extended', 'conservative' or 'plain'.")
      .def_property_readonly(
          "fixed_size", [](const PyKalmanFilter& k) { return k.core().fixed_size(); },
          "True when the fixed-size C++ filter runs (m = 2, 3 or 20 with r = 1).");

  py::class_<PyExactFilter, PyFilter> ex(mod, "ExactFilter");
  ex.def(py::init<const estimation::FilterModel&, uint64_t, uint64_t>(), py::arg("model"),
         py::arg("max_states") = estimation::ExactFilterOptions{}.max_states,
         py::arg("cache_bytes") = estimation::ExactFilterOptions{}.cache_bytes)
      .def_property_readonly(
          "probabilities",
          [](const PyExactFilter& f) {
            const auto& p = f.filter().probabilities();
            return FromVector(Eigen::Map<const Eigen::VectorXd>(p.data(), p.size()));
          },
          "The belief: one probability per count vector (see states).")
      .def_property_readonly(
          "states",
          [](const PyExactFilter& f) {
            const size_t S = f.filter().num_count_vectors();
            Eigen::MatrixXd X(S, f.model().num_states());
            for (size_t k = 0; k < S; ++k) X.row(k) = f.filter().State(k).transpose();
            return FromMatrix(X);
          },
          "The count vectors, S x m (row k has probability probabilities[k]).")
      .def(
          "set_probabilities",
          [](PyExactFilter& f, const py::object& p) {
            const Eigen::VectorXd v = ToVector(p, "probabilities");
            Check(f.filter().SetProbabilities(std::vector<double>(v.data(), v.data() + v.size())));
          },
          py::arg("p"), "Replaces the belief (S non-negative entries summing to 1).")
      .def_property_readonly(
          "num_count_vectors",
          [](const PyExactFilter& f) { return f.filter().num_count_vectors(); },
          "S = C(N + m - 1, m - 1).");

  py::class_<PyParticleFilter, PyFilter> pf(mod, "ParticleFilter");
  pf.def(py::init<const estimation::FilterModel&, int, double, uint64_t>(), py::arg("model"),
         py::arg("particles") = 1000, py::arg("resample_threshold") = 0.5, py::arg("seed") = 1)
      .def_property_readonly(
          "ess", [](const PyParticleFilter& f) { return f.filter().EffectiveSampleSize(); },
          "Effective sample size of the weights.")
      .def_property_readonly(
          "num_particles", [](const PyParticleFilter& f) { return f.filter().num_particles(); },
          "Number of particles.")
      .def_property_readonly(
          "particles",
          [](const PyParticleFilter& f) {
            const int n = f.filter().num_particles();
            Eigen::MatrixXd X(n, f.model().num_states());
            for (int k = 0; k < n; ++k) X.row(k) = f.filter().Particle(k).transpose();
            return FromMatrix(X);
          },
          "The particles' counts, num_particles x m.");

  mod.def("filter_log", &FilterLog, py::arg("model_path"), py::arg("log_path"),
          py::arg("estimator") = "extended", py::arg("particles") = 1000, py::arg("seed") = 1,
          "`recruit filter` over a log file -> the output CSV text.");
}

}  // namespace recruit::py_bind
