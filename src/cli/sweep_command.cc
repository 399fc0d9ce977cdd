// recruit sweep: a grid of closed-loop runs over the controller axes (dT x lambda x estimator x
// seeds) and, from a sweep file, plant axes (any task parameter, plugin config keys of the model)
// on all cores; resumable; one shard of it (--shard K/N) for job arrays, and `recruit sweep merge`
// to join shards into the table an unsharded sweep writes. Writes table.csv/.md, report.md/.html
// with the recommended dT per plant point, sensitivities and figures (docs/sweep.md).
#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <mutex>
#include <set>

#include "cli/command_modules.h"
#include "cli/commands.h"
#include "cli/errors.h"
#include "common/atomic_file.h"
#include "common/content_hash.h"
#include "common/file_lock.h"
#include "common/json_file.h"
#include "common/mujoco_load.h"
#include "common/output_path.h"
#include "sweep/grid.h"
#include "sweep/latency.h"
#include "sweep/sweep_file.h"
#include "sweep/sweep_report.h"
#include "sweep/table.h"

namespace recruit::cli {
namespace {

namespace fs = std::filesystem;

struct SweepArgs {
  std::string task;
  std::string sweep_file;
  std::string out = "sweep";
  std::vector<double> dTs{0.25, 0.5, 1.0, 2.0};
  std::vector<double> lambdas{0.2};
  std::vector<std::string> estimators{"output", "kalman-augmented"};
  int seeds = 20;
  std::uint64_t base_seed = 1;
  int threads = 0;
  double duration = 0;
  std::string filter_model;
  sweep::TrackingCriterion criterion;
  bool progress = false;
  std::string shard;                // "K/N"
  std::vector<std::string> shards;  // merge: the shards' output folders
  // Which options were given on the command line (they override the sweep file's).
  std::set<std::string> given;
};

// Content of a file for the resume key ("" plus a marker when it cannot be read: the run itself
// will then fail and report it).
std::string ContentOf(const std::string& path) {
  if (path.empty()) return "<none>";
  auto text = ReadFile(path);
  return text.ok() ? *text : "<unreadable " + path + ">";
}

// One plant point made concrete: the task (its model possibly a generated variant) and the texts
// its runs' resume key is made of.
struct PlantTask {
  sim::Task task;
  std::string task_text;   // the task document with the point's values (model path as given)
  std::string model_text;  // the model the runs load
};

// The resume key of one run: a hash of everything that determines its result (the plant
// point's task document and model text, the filter model file's content when one is given, the
// run's options and the code version), so an edited input or a new build is never served an old
// result. Without a filter model file, kalman-augmented finds or identifies the model of the
// plant and dT (identification/model_cache.h): both are in the hash already.
std::string RunInputHash(const PlantTask& p, const sweep::SweepSpec& spec, const sweep::SweepRun& g,
                         std::map<std::string, std::string>& cache) {
  sim::RunOptions o;
  o.estimator = g.estimator;
  o.dT = g.dT;
  o.lambda = g.lambda;
  o.filter_model = spec.filter_model;
  const sim::ControllerSettings c = sim::EffectiveSettings(p.task, o);
  auto content = [&cache](const std::string& path) -> const std::string& {
    auto it = cache.find(path);
    if (it == cache.end()) it = cache.emplace(path, ContentOf(path)).first;
    return it->second;
  };
  ContentHash h;
  h.Add(CodeVersion()).Add(p.task_text).Add(p.model_text).Add(content(c.filter_model));
  h.Add(c.estimator).Add(fmt::format("{:.17g} {:.17g} {:.17g}", c.dT, c.lambda, c.force_noise_std));
  h.Add(fmt::format("{:.17g} {}", spec.duration ? *spec.duration : p.task.duration, g.seed));
  return h.Hex();
}

// Everything a sweep and a merge share: the sweep definition resolved into its grid.
struct Prepared {
  sweep::SweepFile file;
  std::string task_path;
  sim::Task task;  // the task as given
  sweep::SweepSpec spec;
  sweep::TrackingCriterion criterion;
  std::vector<PlantTask> plant;
  std::vector<sweep::SweepRun> grid;
  std::string description;
};

struct Failure {
  std::string message;
  int code;
};

Result<Prepared> Prepare(const SweepArgs& a, int* code) {
  Prepared p;
  *code = exit_code::kBadInput;
  if (!a.sweep_file.empty()) {
    auto f = sweep::SweepFile::FromFile(a.sweep_file);
    if (!f.ok()) {
      *code = exit_code::Of(f.code());
      return Error{f.error(), f.code()};
    }
    p.file = std::move(f).value();
  }
  p.task_path = a.given.count("task") || p.file.task.empty() ? a.task : p.file.task;
  if (p.task_path.empty()) {
    *code = exit_code::kUsage;
    return Error{"no task: give --task or \"task\" in the sweep file"};
  }
  auto task_text = ReadFile(p.task_path);
  if (!task_text.ok()) {
    *code = exit_code::kIo;
    return Error{task_text.error(), task_text.code()};
  }
  auto task = sim::Task::FromJsonText(*task_text, p.task_path);
  if (!task.ok()) return Error{task.error(), task.code()};
  p.task = std::move(task).value();

  // Controller axes: the command line's when given, else the sweep file's, else the defaults.
  auto pick = [&](const char* name, const auto& cli, const auto& file) {
    return a.given.count(name) || file.empty() ? cli : file;
  };
  sweep::SweepSpec& spec = p.spec;
  spec.dTs = pick("dT", a.dTs, p.file.dTs);
  spec.lambdas = pick("lambda", a.lambdas, p.file.lambdas);
  spec.estimators = pick("estimator", a.estimators, p.file.estimators);
  spec.seeds = a.given.count("seeds") || !p.file.seeds ? a.seeds : *p.file.seeds;
  spec.identify_missing_models = true;  // as simulate does: a missing model is identified, cached
  spec.base_seed =
      a.given.count("base-seed") || !p.file.base_seed ? a.base_seed : *p.file.base_seed;
  if (a.duration > 0) {
    spec.duration = a.duration;
  } else if (p.file.duration) {
    spec.duration = p.file.duration;
  }
  if (!a.filter_model.empty()) spec.filter_model = a.filter_model;
  p.criterion = a.criterion;
  if (p.file.criterion) {
    if (!a.given.count("max-overshoot"))
      p.criterion.max_overshoot = p.file.criterion->max_overshoot;
    if (!a.given.count("min-settled")) p.criterion.min_settled = p.file.criterion->min_settled;
  }

  auto points = sweep::PlantPoints(p.file);
  if (!points.ok()) return Error{points.error(), points.code()};
  spec.plant = p.file.axes.empty() ? std::vector<sweep::PlantPoint>{} : *points;

  // Each plant point: apply it, write an edited model under <out>/models (named by its content),
  // and parse the task, so a bad path or value fails now, naming the axis and value.
  const std::string where = "sweep file '" + a.sweep_file + "'";
  std::string model_text;
  if (!p.file.axes.empty()) {
    auto m = ReadFile(p.task.model_path);
    if (!m.ok()) {
      *code = exit_code::kIo;
      return Error{m.error(), m.code()};
    }
    model_text = *m;
  }
  std::map<std::string, std::string> contents;
  for (size_t i = 0; i < points->size(); ++i) {
    const sweep::PlantPoint& pt = (*points)[i];
    PlantTask pl;
    if (p.file.axes.empty()) {
      pl.task = p.task;
      pl.task_text = *task_text;
      pl.model_text = ContentOf(p.task.model_path);
      p.plant.push_back(std::move(pl));
      continue;
    }
    std::string label = where + ": plant point " + std::to_string(i);
    for (const auto& [name, v] : pt.values) label += fmt::format(" {}={:g}", name, v);
    auto in = sweep::ApplyPlantPoint(*task_text, model_text, p.file.axes, pt, where);
    if (!in.ok()) return Error{in.error(), in.code()};
    pl.task_text = in->task_text;
    pl.model_text = in->model_text;
    std::string text = in->task_text;
    if (in->model_edited) {
      if (model_text.find("file=") != std::string::npos) {
        return Error{label +
                     ": model axes need a model without file references (meshes, "
                     "includes): '" +
                     p.task.model_path + "' has file=..."};
      }
      ContentHash h;
      h.Add(in->model_text);
      const fs::path dir = fs::path(a.out) / "models";
      std::error_code ec;
      fs::create_directories(dir, ec);
      const fs::path file = fs::absolute(
          dir / (fs::path(p.task.model_path).stem().string() + "_" + h.Hex() + ".xml"));
      if (!fs::exists(file, ec)) {
        if (Status s = WriteFileAtomically(file.string(), in->model_text); !s.ok()) {
          *code = exit_code::kIo;
          return Error{s.error(), s.code()};
        }
        auto m = LoadModel(file.string());
        if (!m.ok()) {
          std::error_code ignore;
          fs::remove(file, ignore);
          return Error{label + ": the edited model does not load: " + m.error(), m.code()};
        }
      }
      auto doc = nlohmann::json::parse(text);
      doc["model"] = file.string();
      text = doc.dump(1);
    }
    auto t = sim::Task::FromJsonText(text, p.task_path);
    if (!t.ok()) return Error{label + ": " + t.error(), t.code()};
    pl.task = std::move(t).value();
    p.plant.push_back(std::move(pl));
  }
  auto grid = sweep::ExpandGrid(spec);
  if (!grid.ok()) {
    *code = exit_code::kUsage;
    return Error{grid.error(), grid.code()};
  }
  p.grid = std::move(grid).value();
  for (auto& g : p.grid) g.input_hash = RunInputHash(p.plant[g.plant], spec, g, contents);

  std::string axes;
  for (const auto& ax : p.file.axes) axes += fmt::format(" x {} ({})", ax.name, ax.path);
  const char* sampling[] = {"grid", "Latin-hypercube sample", "Sobol sample"};
  p.description = fmt::format(
      "Swept: {} plant point{} ({}{}) x dT {{{}}} x lambda {{{}}} x estimator {{{}}} x {} seeds "
      "= {} runs of {:g} s.",
      p.plant.size(), p.plant.size() == 1 ? "" : "s",
      p.file.axes.empty() ? "the task as given" : sampling[static_cast<int>(p.file.sampling)], axes,
      fmt::join(spec.dTs, ", "), fmt::join(spec.lambdas, ", "), fmt::join(spec.estimators, ", "),
      spec.seeds, p.grid.size(), spec.duration ? *spec.duration : p.task.duration);
  return p;
}

// Table, stability map and the report with figures.
int WriteReports(const std::string& cmd, const Prepared& p,
                 const std::vector<sim::RunSummary>& runs, const std::string& out) {
  const auto cells = sweep::Aggregate(p.grid, runs, p.criterion);
  if (Status s = sweep::WriteTables(cells, p.criterion, out, p.task.name); !s.ok()) {
    return Fail(cmd, s.error(), exit_code::kIo);
  }
  // The figures are drawn by the plot module (cairo), opened only now.
  std::string error;
  const PlotModule* plot = OpenPlotModule(&error);
  if (!plot) return Fail(cmd, error, exit_code::kIo);
  if (p.file.axes.empty()) {  // the dT x lambda map, as `recruit plot --stability-map` draws it
    const plot::PlotOptions map =
        sweep::StabilityMapOptions(out, p.task.name, static_cast<int>(p.spec.estimators.size()));
    std::vector<std::string> written;
    Error failed;
    plot->run(&map, &written, &failed);
    if (!failed.message.empty())
      return Fail(cmd, "stability map: " + failed.message, exit_code::kIo);
  }
  auto render = [plot](const plot::Figure& fig, int w, int h,
                       plot::Format f) -> Result<std::string> {
    std::string bytes;
    Error why;
    plot->figure(&fig, w, h, f, &bytes, &why);
    if (!why.message.empty()) return why;
    return bytes;
  };
  sweep::ReportInput in{p.task.name, p.description, p.criterion, cells, {}};
  // The output-only loop's latency bound needs each plant point's force latency (one open-loop
  // step of its model, ~0.1 s each); a point whose model cannot do it gets none (NaN).
  if (std::find(p.spec.estimators.begin(), p.spec.estimators.end(), "output") !=
      p.spec.estimators.end()) {
    in.latency.assign(p.plant.size(), std::nan(""));
    tbb::parallel_for(size_t{0}, p.plant.size(), [&](size_t i) {
      auto tau = sweep::ForceLatency(p.plant[i].task);
      if (tau.ok()) in.latency[i] = *tau;
    });
  }
  if (Status s = sweep::WriteReport(in, out, render); !s.ok())
    return Fail(cmd, s.error(), exit_code::kIo);
  return exit_code::kOk;
}

// Checks the outputs replace no input (exit 2), creates `out` and takes its lock (exit 4).
Result<FileLock> OpenOut(const std::string& out, const Prepared& p, const SweepArgs& a, int* code) {
  *code = exit_code::kUsage;
  // The outputs must not replace the inputs (a task file kept in the output folder).
  for (const char* name :
       {"sweep.json", "table.csv", "table.md", "stability.dat", "stability.png", "sweep.lock",
        "report.md", "report.html", "shard.json", "progress.log"}) {
    Status s = CheckNotAnInput((fs::path(out) / name).string(), "output",
                               {{"--task", p.task_path},
                                {"--sweep", a.sweep_file},
                                {"--filter-model", a.filter_model},
                                {"the task's model", p.task.model_path}});
    if (!s.ok()) return Error{s.error(), s.code()};
  }
  *code = exit_code::kIo;
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec)
    return Error{"cannot create --out '" + ShortText(out) + "': " + ec.message(), ErrorCode::kIo};
  return FileLock::TryLock((fs::path(out) / "sweep.lock").string());
}

int RunSweepCommand(const SweepArgs& a) {
  const std::string cmd = "sweep";
  int code = 0;
  auto prep = Prepare(a, &code);
  if (!prep.ok()) return Fail(cmd, prep.error(), code);
  const Prepared& p = *prep;
  int shard_k = 1, shard_n = 1;
  if (!a.shard.empty()) {
    auto s = sweep::ParseShard(a.shard);
    if (!s.ok()) return Fail(cmd, s.error(), exit_code::kUsage);
    std::tie(shard_k, shard_n) = *s;
  }
  const std::vector<sweep::SweepRun> todo =
      a.shard.empty() ? p.grid : sweep::ShardOf(p.grid, shard_k, shard_n);

  // One sweep per folder at a time: the lock is held until the process ends.
  int lock_code = 0;
  auto lock = OpenOut(a.out, p, a, &lock_code);
  if (!lock.ok()) return Fail(cmd, lock.error(), lock_code);
  // A folder holds one sweep (or one shard of it): its id must match to resume. Which runs can
  // be reused is decided per run by its input hash (an edited task reruns everything).
  const std::string id_path = (fs::path(a.out) / "sweep.json").string();
  nlohmann::json id = {{"task", fs::absolute(p.task_path).lexically_normal().string()},
                       {"duration", p.spec.duration ? *p.spec.duration : p.task.duration},
                       {"filter_model", a.filter_model}};
  if (!a.sweep_file.empty()) id["sweep"] = fs::absolute(a.sweep_file).lexically_normal().string();
  if (!a.shard.empty()) id["shard"] = a.shard;
  std::error_code ec;  // a path the system refuses fails below, when the sweep writes it
  if (fs::exists(id_path, ec)) {
    auto old = LoadJsonFile(id_path);
    if (!old.ok()) return Fail(cmd, old.failure());
    if (*old != id) {
      return Fail(
          cmd,
          "'" + ShortText(a.out) + "' holds another sweep (" + id_path + "); use another --out",
          exit_code::kUsage);
    }
  } else if (Status s = WriteFileAtomically(id_path, id.dump(2) + "\n"); !s.ok()) {
    return Fail(cmd, s.error(), exit_code::kIo);
  }

  sweep::SweepSpec spec = p.spec;
  auto run = [&p, &spec](const sweep::SweepRun& g) {
    return sim::RunTask(p.plant[g.plant].task, sweep::RunOptionsFor(g, spec));
  };
  // Progress and the remaining time on stderr: in place on a terminal, else (a batch job's log)
  // a line at most every 10 s. The estimate uses the runs made now (not those reused).
  const bool tty = ::isatty(STDERR_FILENO);
  const bool progress = a.progress || tty;
  std::mutex mu;
  const auto t0 = std::chrono::steady_clock::now();
  int first_done = -1;
  double last_line = -1e9;
  auto report = [&](int done, int total) {
    if (!progress) return;
    std::lock_guard<std::mutex> l(mu);
    if (first_done < 0) first_done = done - 1;
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const int made = done - first_done;
    const double eta = el / made * (total - done);
    if (!tty && done != total && el - last_line < 10) return;
    last_line = el;
    std::fprintf(stderr, "%s  %d / %d runs, %.0f s elapsed, ETA %.0f s%s", tty ? "\r" : "", done,
                 total, el, eta, tty && done != total ? "   " : "\n");
  };
  std::cerr << "recruit sweep: " << todo.size() << " runs"
            << (a.shard.empty()
                    ? ""
                    : " (shard " + a.shard + " of " + std::to_string(p.grid.size()) + ")")
            << " into " << a.out << " (per-run log: " << (fs::path(a.out) / "progress.log").string()
            << ")\n";
  auto outcome = sweep::RunSweep(todo, a.out, run, a.threads, report);
  if (!outcome.ok()) {
    return Fail(cmd, outcome.error() + " (finished runs are kept; run again to resume)",
                exit_code::Of(outcome.code()));
  }
  double wall = 0, simulated = 0;
  for (const auto& r : outcome->runs) {
    wall += r.wall_seconds;
    simulated += r.duration;
  }
  if (!a.shard.empty()) {
    // The shard's manifest: merge checks it belongs to the same sweep.
    nlohmann::json m = {{"sweep_id", sweep::SweepId(p.grid)},
                        {"shard", shard_k},
                        {"of", shard_n},
                        {"runs", todo.size()}};
    if (Status s = WriteFileAtomically((fs::path(a.out) / "shard.json").string(), m.dump(2) + "\n");
        !s.ok())
      return Fail(cmd, s.error(), exit_code::kIo);
    std::cout << "recruit sweep: shard " << a.shard << ": " << outcome->executed << " runs made, "
              << outcome->reused << " reused; " << simulated << " s simulated in " << wall
              << " s of run time; join the shards with `recruit sweep merge`\n";
    return exit_code::kOk;
  }
  if (int rc = WriteReports(cmd, p, outcome->runs, a.out); rc != 0) return rc;
  std::cout << "recruit sweep: " << outcome->executed << " runs made, " << outcome->reused
            << " reused; " << simulated << " s simulated in " << wall
            << " s of run time; wrote table.csv, table.md, report.md, report.html in " << a.out
            << "\n";
  auto md = ReadFile((fs::path(a.out) / "table.md").string());
  if (md.ok()) {
    const auto pos = md->find("## Shortest");
    if (pos != std::string::npos) std::cout << md->substr(pos);
  }
  return exit_code::kOk;
}

// recruit sweep merge: the shards' run records, checked against the sweep recomputed from the
// same definition, copied into --out and reported exactly as an unsharded sweep.
int RunMergeCommand(const SweepArgs& a) {
  const std::string cmd = "sweep merge";
  int code = 0;
  auto prep = Prepare(a, &code);
  if (!prep.ok()) return Fail(cmd, prep.error(), code);
  const Prepared& p = *prep;
  const std::string id = sweep::SweepId(p.grid);
  std::map<int, fs::path> dirs;
  int n = 0;
  for (const auto& d : a.shards) {
    const std::string mpath = (fs::path(d) / "shard.json").string();
    std::error_code ec;
    if (!fs::exists(mpath, ec)) {
      std::cerr << "recruit sweep merge: '" << d << "' has no shard.json (unfinished shard)\n";
      continue;
    }
    auto m = LoadJsonFile(mpath);
    if (!m.ok()) return Fail(cmd, m.failure());
    if (!m->is_object() || !m->contains("sweep_id") || !m->contains("shard") ||
        !m->contains("of") || !(*m)["shard"].is_number_integer() ||
        !(*m)["of"].is_number_integer()) {
      return Fail(cmd, mpath + ": not a shard manifest", exit_code::kBadInput);
    }
    if ((*m)["sweep_id"] != id) {
      return Fail(cmd,
                  mpath +
                      ": a shard of another sweep (other task, axes, options or build; its "
                      "sweep_id " +
                      (*m)["sweep_id"].dump() + ", this sweep's \"" + id + "\")",
                  exit_code::kBadInput);
    }
    const int k = (*m)["shard"], of = (*m)["of"];
    if (n != 0 && of != n) {
      return Fail(cmd, fmt::format("{}: shard {}/{} among shards of {}", mpath, k, of, n),
                  exit_code::kBadInput);
    }
    n = of;
    if (dirs.count(k)) {
      return Fail(cmd, fmt::format("shard {} given twice ('{}', '{}')", k, dirs[k].string(), d),
                  exit_code::kUsage);
    }
    dirs[k] = d;
  }
  if (n == 0) return Fail(cmd, "no finished shard among the folders given", exit_code::kBadInput);
  std::vector<int> missing;
  for (int k = 1; k <= n; ++k) {
    if (!dirs.count(k)) missing.push_back(k);
  }
  int lock_code = 0;
  auto lock = OpenOut(a.out, p, a, &lock_code);
  if (!lock.ok()) return Fail(cmd, lock.error(), lock_code);
  const fs::path runs_dir = fs::path(a.out) / "runs";
  std::error_code ec;
  fs::create_directories(runs_dir, ec);
  if (ec) return Fail(cmd, "cannot create '" + runs_dir.string() + "': " + ec.message(), 4);
  std::set<int> incomplete(missing.begin(), missing.end());
  for (const auto& g : p.grid) {
    const int k = g.index % n + 1;
    if (!dirs.count(k)) continue;
    const fs::path src = dirs[k] / "runs" / (g.Key() + ".json");
    auto rec = LoadJsonFile(src.string());
    if (!rec.ok() || !rec->is_object() || rec->value("input_hash", "") != g.input_hash) {
      incomplete.insert(k);
      continue;
    }
    auto text = ReadFile(src.string());
    if (!text.ok()) return Fail(cmd, text.error(), exit_code::kIo);
    if (Status s = WriteFileAtomically((runs_dir / (g.Key() + ".json")).string(), *text); !s.ok())
      return Fail(cmd, s.error(), exit_code::kIo);
  }
  if (!incomplete.empty()) {
    return Fail(cmd,
                fmt::format("shards {} of {} are missing or incomplete; rerun them (each resumes "
                            "its finished runs), e.g. sbatch --array={} scripts/slurm/"
                            "sweep_array.sh ..., then merge again",
                            fmt::join(incomplete, ","), n, fmt::join(incomplete, ",")),
                exit_code::kBadInput);
  }
  // Every run is now recorded in --out: RunSweep only reads them back.
  auto none = [](const sweep::SweepRun& g) -> Result<sim::RunSummary> {
    return Error{"run " + g.Key() + " missing after merge"};
  };
  auto outcome = sweep::RunSweep(p.grid, a.out, none, 1);
  if (!outcome.ok()) return Fail(cmd, outcome.error(), exit_code::kInternal);
  if (int rc = WriteReports(cmd, p, outcome->runs, a.out); rc != 0) return rc;
  std::cout << "recruit sweep merge: " << n << " shards, " << outcome->reused
            << " runs; wrote table.csv, table.md, report.md, report.html in " << a.out << "\n";
  return exit_code::kOk;
}

// The options shared by `sweep` and `sweep merge` (the sweep's definition must be the same).
void AddDefinitionOptions(CLI::App* cmd, SweepArgs* a) {
  auto track = [a](CLI::Option* o, const std::string& name) {
    o->each([a, name](const std::string&) { a->given.insert(name); });
    return o;
  };
  track(cmd->add_option("--task", a->task, "Task file (JSON, docs/formats/task.md)")
            ->check(CLI::ExistingFile),
        "task");
  cmd->add_option("--sweep", a->sweep_file,
                  "Sweep file (JSON, docs/sweep.md): task, controller and plant axes; options "
                  "given here override its values")
      ->check(CLI::ExistingFile);
  track(cmd->add_option("--dT", a->dTs, "Sampling periods, s, comma separated")
            ->delimiter(',')
            ->check(Positive())
            ->capture_default_str(),
        "dT");
  track(cmd->add_option("--lambda", a->lambdas, "Law gains in (0, 1], comma separated")
            ->delimiter(',')
            ->check(Fraction())
            ->capture_default_str(),
        "lambda");
  track(cmd->add_option("--estimator", a->estimators,
                        "Estimators, comma separated (output, kalman2, kalman-augmented)")
            ->delimiter(',')
            ->check(CLI::IsMember({"output", "kalman2", "kalman-augmented"}))
            ->capture_default_str(),
        "estimator");
  track(cmd->add_option("--seeds", a->seeds, "Seeds per grid cell, 1..100000")
            ->check(CLI::Range(1, 100000))
            ->capture_default_str(),
        "seeds");
  track(cmd->add_option("--base-seed", a->base_seed,
                        "Run seeds are Rng::DeriveSeed(base, seed index)")
            ->capture_default_str(),
        "base-seed");
  cmd->add_option("--duration", a->duration, "Simulated time per run, s [default: task's]")
      ->check(Positive());
  cmd->add_option("--filter-model", a->filter_model,
                  "Filter model file for kalman-augmented [default: the one identified for "
                  "each dT, models/identified/]")
      ->check(CLI::ExistingFile);
  track(cmd->add_option("--max-overshoot", a->criterion.max_overshoot,
                        "Criterion: mean step overshoot at most this fraction (>= 0)")
            ->check(NonNegative())
            ->capture_default_str(),
        "max-overshoot");
  track(cmd->add_option("--min-settled", a->criterion.min_settled,
                        "Criterion: at least this fraction of steps settle in the band, [0, 1]")
            ->check(NumberIn(0, false, 1, "in [0, 1]"))
            ->capture_default_str(),
        "min-settled");
}

}  // namespace

void AddSweepCommand(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<SweepArgs>();
  auto* cmd = app.add_subcommand(
      "sweep",
      "Run a task over controller axes (dT x lambda x estimator x seeds) and plant axes from a "
      "sweep file on all cores (resumable, shardable) and write a table, a report with the "
      "recommended dT per plant point, sensitivities and figures");
  AddDefinitionOptions(cmd, args.get());
  cmd->add_option("--out", args->out, "Output directory (runs/ inside it makes it resumable)")
      ->capture_default_str();
  cmd->add_option("--threads", args->threads, "Worker threads, 0..4096 (0 = all cores)")
      ->check(CLI::Range(0, 4096))
      ->capture_default_str();
  cmd->add_option("--shard", args->shard,
                  "Run only shard K of N (K/N, 1 <= K <= N): runs with grid index % N == K-1; "
                  "join the shards' folders with `recruit sweep merge`");
  cmd->add_flag("--progress", args->progress,
                "Show progress and the remaining time even when stderr is not a terminal");

  auto margs = std::make_shared<SweepArgs>();
  auto* merge = cmd->add_subcommand(
      "merge",
      "Join the output folders of `recruit sweep --shard K/N` runs into the table and report an "
      "unsharded sweep writes (give the same sweep definition: --sweep/--task and options)");
  AddDefinitionOptions(merge, margs.get());
  merge->add_option("--out", margs->out, "Output directory of the merged sweep")->required();
  merge->add_option("shards", margs->shards, "The shards' output folders")->required();
  merge->callback([margs, &exit_code] { exit_code = RunMergeCommand(*margs); });
  cmd->callback([args, merge, &exit_code] {
    if (merge->parsed()) return;
    exit_code = RunSweepCommand(*args);
  });
}

}  // namespace recruit::cli
