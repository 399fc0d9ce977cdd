// Runs from Python: simulate (one closed-loop run of a task, with its per-step trace), sweep (a
// grid of runs on all cores) and aggregate (a sweep's runs per grid cell, as `recruit sweep`'s
// table.csv). Long runs release the GIL.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <optional>
#include <set>
#include <string>
#include <vector>

#include "bindings.h"
#include "common/step_observer.h"
#include "convert.h"
#include "sim/run_task.h"
#include "sim/task.h"
#include "sweep/grid.h"
#include "sweep/sweep.h"
#include "sweep/table.h"

namespace recruit::py_bind {
namespace {

// Collects the per-step CSV's columns (sim/csv_writer.cc: same rows, same names) at full
// precision: every `every`-th physics step and every control instant.
class TraceRecorder : public StepObserver {
 public:
  explicit TraceRecorder(int every) : every_(every < 1 ? 1 : every) {}

  Status OnStep(const mjModel*, const mjData*, const TelemetrySample& s) override {
    if (names_.empty()) {
      names_ = {"time", "reference", "measured", "angle"};
      for (const auto& b : s.bundles) {
        for (const char* col : {"force", "force_reference", "true_on", "estimated_on",
                                "estimated_on_std", "p_on", "p_off", "mean_temperature"}) {
          names_.push_back(b.actuator + "." + col);
        }
      }
      names_.push_back("control_instant");
      for (const auto& b : s.bundles) names_.push_back(b.actuator + ".sensed_force");
      cols_.resize(names_.size());
    }
    if (count_++ % every_ != 0 && !s.control_instant) return Status::Ok();
    size_t c = 0;
    for (double v : {s.time, s.reference, s.measured, s.angle}) cols_[c++].push_back(v);
    for (const auto& b : s.bundles) {
      for (double v : {b.force, b.force_reference, static_cast<double>(b.true_on), b.estimated_on,
                       b.estimated_on_std, b.p_on, b.p_off, b.mean_temperature}) {
        if (c + 1 >= cols_.size()) return Error{"trace: the number of bundles changed"};
        cols_[c++].push_back(v);
      }
    }
    cols_[c++].push_back(s.control_instant ? 1.0 : 0.0);
    for (const auto& b : s.bundles) cols_[c++].push_back(b.sensed_force);
    return Status::Ok();
  }

  // Column dict; true_on as int64, control_instant as bool, the rest float64.
  py::dict Columns() const {
    py::dict out;
    for (size_t c = 0; c < names_.size(); ++c) {
      const std::string& n = names_[c];
      const auto& v = cols_[c];
      const bool is_int = n.size() > 8 && n.compare(n.size() - 8, 8, ".true_on") == 0;
      if (n == "control_instant") {
        py::array_t<bool> a(v.size());
        for (size_t i = 0; i < v.size(); ++i) a.mutable_data()[i] = v[i] != 0.0;
        out[n.c_str()] = a;
      } else if (is_int) {
        py::array_t<int64_t> a(v.size());
        for (size_t i = 0; i < v.size(); ++i) a.mutable_data()[i] = static_cast<int64_t>(v[i]);
        out[n.c_str()] = a;
      } else {
        py::array_t<double> a(v.size());
        std::copy(v.begin(), v.end(), a.mutable_data());
        out[n.c_str()] = a;
      }
    }
    return out;
  }

 private:
  int every_;
  long count_ = 0;
  std::vector<std::string> names_;
  std::vector<std::vector<double>> cols_;
};

template <class T>
std::optional<T> Opt(const py::object& o) {
  if (o.is_none()) return std::nullopt;
  return o.cast<T>();
}

// -> (summary JSON text, trace column dict or None).
py::tuple Simulate(const std::string& task_path, const py::object& estimator,
                   const py::object& filter_model, const py::object& dT, const py::object& lambda,
                   const py::object& force_noise_std, const py::object& duration, uint64_t seed,
                   int trace_every) {
  if (trace_every < 0) Fail("trace_every: must be >= 0 (0: no trace)");
  sim::Task task = Take(sim::Task::FromFile(task_path));
  sim::RunOptions opt;
  opt.estimator = Opt<std::string>(estimator);
  opt.filter_model = Opt<std::string>(filter_model);
  opt.dT = Opt<double>(dT);
  opt.lambda = Opt<double>(lambda);
  opt.force_noise_std = Opt<double>(force_noise_std);
  opt.duration = Opt<double>(duration);
  opt.seed = seed;
  opt.identify_missing_models = true;  // as `recruit simulate` does
  TraceRecorder trace(trace_every);
  std::vector<StepObserver*> observers;
  if (trace_every > 0) observers.push_back(&trace);
  std::optional<Result<sim::RunSummary>> r;
  {
    py::gil_scoped_release release;
    r.emplace(sim::RunTask(task, opt, observers));
  }
  const sim::RunSummary s = Take(std::move(*r));
  return py::make_tuple(s.ToJson().dump(),
                        trace_every > 0 ? py::object(trace.Columns()) : py::object(py::none()));
}

// The runs of a sweep as one JSON array text, prepared as `recruit sweep` prepares them
// (sweep::Prepare: the sweep file's controller values and plant axes under the options `given`,
// the task of each plant point, the grid, each run's input hash) and run as it runs them; each
// run's summary gets its grid position (seed_index, plant, plant_values). `out_dir` holds the
// per-run records (RunSweep's resume files) and the models of the plant points.
std::string Sweep(const std::string& task_path, const py::object& sweep_file,
                  const std::vector<double>& dTs, const std::vector<double>& lambdas,
                  const std::vector<std::string>& estimators, int seeds, uint64_t base_seed,
                  const std::vector<std::string>& given, const py::object& duration,
                  const py::object& filter_model, int threads, const std::string& out_dir) {
  if (threads < 0) Fail("threads: must be >= 0 (0: all cores)");
  sweep::SweepDefinition d;
  d.task = task_path;
  d.sweep_file = Opt<std::string>(sweep_file).value_or("");
  d.out = out_dir;
  d.dTs = dTs;
  d.lambdas = lambdas;
  d.estimators = estimators;
  d.seeds = seeds;
  d.base_seed = base_seed;
  d.given = std::set<std::string>(given.begin(), given.end());
  if (const std::optional<double> t = Opt<double>(duration)) {
    if (!(*t > 0)) Fail("duration: must be > 0 s");
    d.duration = *t;  // else the sweep file's, else the task's
  }
  d.filter_model = Opt<std::string>(filter_model).value_or("");
  d.identify_missing_models = true;  // as `recruit sweep` does
  const sweep::PreparedSweep p = Take(sweep::Prepare(d));
  // As sweep::Run runs each grid point.
  auto run = [&p](const sweep::SweepRun& g) {
    return sim::RunTask(p.plant[g.plant].task, sweep::RunOptionsFor(g, p.spec));
  };
  std::optional<Result<sweep::SweepOutcome>> outcome;
  {
    py::gil_scoped_release release;
    outcome.emplace(sweep::RunSweep(p.grid, out_dir, run, threads));
  }
  const sweep::SweepOutcome o = Take(std::move(*outcome));
  nlohmann::json runs = nlohmann::json::array();
  for (size_t i = 0; i < o.runs.size(); ++i) {
    nlohmann::json j = o.runs[i].ToJson();
    j["seed_index"] = p.grid[i].seed_index;
    j["plant"] = p.grid[i].plant;
    j["plant_values"] = nlohmann::json::array();
    for (const auto& [name, v] : p.grid[i].plant_values) j["plant_values"].push_back({name, v});
    runs.push_back(std::move(j));
  }
  return runs.dump();
}

// Cells of a run column dict (sweep's): per (dT, lambda, estimator), as table.csv. The metric
// columns come from sim::kMetricFields: those the cells aggregate are read, the cells' written.
// With plant axes (sweep(..., sweep_file=...)) the cells are per plant point too: `plant_axes`
// names the axis columns, and runs has a "plant" column.
py::dict AggregateColumns(const py::dict& runs, double max_overshoot, double min_settled,
                          const std::vector<std::string>& plant_axes) {
  if (!runs.contains("estimator")) Fail("aggregate: runs has no column 'estimator'");
  const auto est = runs["estimator"].cast<std::vector<std::string>>();
  const Eigen::Index n = static_cast<Eigen::Index>(est.size());
  auto column = [&runs, n](const std::string& name) {
    if (!runs.contains(name)) Fail("aggregate: runs has no column '" + name + "'");
    Eigen::VectorXd v = ToVector(runs[py::str(name)], name);
    if (v.size() != n) Fail("aggregate: the columns of runs differ in length");
    return v;
  };
  const Eigen::VectorXd dT = column("dT"), lambda = column("lambda");
  std::vector<sim::RunSummary> rs(n);
  std::vector<sweep::SweepRun> grid(n);
  const Eigen::VectorXd plant = plant_axes.empty() ? Eigen::VectorXd::Zero(n) : column("plant");
  std::vector<Eigen::VectorXd> axes;
  for (const auto& name : plant_axes) axes.push_back(column(name));
  for (Eigen::Index i = 0; i < n; ++i) {
    rs[i].dT = grid[i].dT = dT(i);
    rs[i].lambda = grid[i].lambda = lambda(i);
    rs[i].estimator = grid[i].estimator = est[i];
    grid[i].plant = static_cast<int>(plant(i));
    for (size_t a = 0; a < axes.size(); ++a)
      grid[i].plant_values.push_back({plant_axes[a], axes[a](i)});
  }
  for (const sim::MetricField& f : sim::kMetricFields) {
    if (!f.cell_mean) continue;
    const Eigen::VectorXd v = column(f.name);
    for (Eigen::Index i = 0; i < n; ++i) sim::SetMetric(rs[i].metrics, f, v(i));
  }
  sweep::TrackingCriterion criterion;
  criterion.max_overshoot = max_overshoot;
  criterion.min_settled = min_settled;
  const std::vector<sweep::CellStats> cells =
      plant_axes.empty() ? sweep::Aggregate(rs, criterion) : sweep::Aggregate(grid, rs, criterion);
  // Column names and order as table.csv (sweep::CellColumns).
  const std::vector<std::string> names = sim::CellMetricColumns();
  std::vector<std::string> estimators;
  std::vector<bool> meets;
  std::vector<int> nseeds;
  std::vector<double> dTs, lambdas, margins;
  std::vector<std::vector<double>> metrics(names.size());
  for (const auto& c : cells) {
    dTs.push_back(c.dT);
    lambdas.push_back(c.lambda);
    estimators.push_back(c.estimator);
    nseeds.push_back(c.seeds);
    const std::vector<double> row = sweep::CellMetricValues(c);
    for (size_t k = 0; k < names.size(); ++k) metrics[k].push_back(row[k]);
    meets.push_back(c.meets);
    margins.push_back(c.margin);
  }
  auto arr = [](const std::vector<double>& x) {
    return FromVector(Eigen::Map<const Eigen::VectorXd>(x.data(), x.size()));
  };
  py::dict out;
  if (!plant_axes.empty()) {  // first, as in table.csv
    std::vector<int> plants;
    for (const auto& c : cells) plants.push_back(c.plant);
    out["plant"] = py::array_t<int>(plants.size(), plants.data());
    for (size_t a = 0; a < plant_axes.size(); ++a) {
      std::vector<double> v;
      for (const auto& c : cells) v.push_back(c.plant_values.at(a).second);
      out[py::str(plant_axes[a])] = arr(v);
    }
  }
  out["dT"] = arr(dTs);
  out["lambda"] = arr(lambdas);
  out["estimator"] = estimators;
  out["seeds"] = py::array_t<int>(nseeds.size(), nseeds.data());
  for (size_t k = 0; k < names.size(); ++k) out[py::str(names[k])] = arr(metrics[k]);
  py::array_t<bool> m(meets.size());
  for (size_t i = 0; i < meets.size(); ++i) m.mutable_data()[i] = meets[i];
  out["meets_criterion"] = m;
  out["margin"] = arr(margins);
  return out;
}

// sim::kMetricFields as a tuple of dicts: name, unit, integer (a count), may_be_nan.
py::tuple MetricFields() {
  py::list out;
  for (const sim::MetricField& f : sim::kMetricFields) {
    py::dict d;
    d["name"] = f.name;
    d["unit"] = f.unit;
    d["integer"] = f.count != nullptr;
    d["may_be_nan"] = f.may_be_nan;
    out.append(d);
  }
  return py::tuple(out);
}

}  // namespace

void BindSim(py::module_& mod) {
  mod.def("simulate_run", &Simulate, py::arg("task_path"), py::arg("estimator") = py::none(),
          py::arg("filter_model") = py::none(), py::arg("dT") = py::none(),
          py::arg("lam") = py::none(), py::arg("force_noise_std") = py::none(),
          py::arg("duration") = py::none(), py::arg("seed") = 1, py::arg("trace_every") = 1,
          "One closed-loop run -> (summary JSON text, trace column dict or None).");
  mod.def("sweep_json", &Sweep, py::arg("task_path"), py::arg("sweep_file"), py::arg("dT"),
          py::arg("lam"), py::arg("estimator"), py::arg("seeds"), py::arg("base_seed"),
          py::arg("given"), py::arg("duration"), py::arg("filter_model"), py::arg("threads"),
          py::arg("out_dir"),
          "A sweep prepared as `recruit sweep` prepares it -> JSON array text of the run "
          "summaries (with seed_index, plant, plant_values).");
  mod.def("aggregate", &AggregateColumns, py::arg("runs"), py::arg("max_overshoot") = 0.10,
          py::arg("min_settled") = 0.90, py::arg("plant_axes") = std::vector<std::string>{},
          "A sweep's run columns -> cell columns (as `recruit sweep`'s table.csv).");
  mod.attr("METRIC_FIELDS") = MetricFields();
  const std::vector<std::string> columns = sweep::CellColumns();
  mod.attr("CELL_COLUMNS") = py::tuple(py::cast(columns));
}

}  // namespace recruit::py_bind
