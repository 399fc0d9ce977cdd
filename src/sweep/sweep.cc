#include "sweep/sweep.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include "common/atomic_file.h"
#include "common/content_hash.h"
#include "common/json_file.h"
#include "common/mujoco_load.h"
#include "common/output_path.h"
#include "common/short_text.h"
#include "common/version.h"
#include "sim/run_task.h"
#include "sweep/latency.h"
#include "sweep/tune.h"

namespace recruit::sweep {
namespace {

namespace fs = std::filesystem;

// Content of a file for the resume key ("" plus a marker when it cannot be read: the run itself
// will then fail and report it).
std::string ContentOf(const std::string& path) {
  if (path.empty()) return "<none>";
  auto text = ReadFile(path);
  return text.ok() ? *text : "<unreadable " + path + ">";
}

// The resume key of one run: a hash of everything that determines its result (the plant
// point's task document and model text, the filter model file's content when one is given, the
// run's options and the code version), so an edited input or a new build is never served an old
// result. Without a filter model file, kalman-augmented finds or identifies the model of the
// plant and dT (identification/model_cache.h): both are in the hash already.
std::string RunInputHash(const PlantTask& p, const SweepSpec& spec, const SweepRun& g,
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

// The controller axes and the criterion: the caller's values when given, else the sweep
// file's, else the defaults.
void ResolveOptions(const SweepDefinition& d, PreparedSweep& p) {
  auto pick = [&](const char* name, const auto& given, const auto& file) {
    return d.given.count(name) || file.empty() ? given : file;
  };
  SweepSpec& spec = p.spec;
  spec.dTs = pick("dT", d.dTs, p.file.dTs);
  spec.lambdas = pick("lambda", d.lambdas, p.file.lambdas);
  spec.estimators = pick("estimator", d.estimators, p.file.estimators);
  spec.seeds = d.given.count("seeds") || !p.file.seeds ? d.seeds : *p.file.seeds;
  spec.identify_missing_models = d.identify_missing_models;
  spec.base_seed =
      d.given.count("base-seed") || !p.file.base_seed ? d.base_seed : *p.file.base_seed;
  if (d.duration > 0) {
    spec.duration = d.duration;
  } else if (p.file.duration) {
    spec.duration = p.file.duration;
  }
  if (!d.filter_model.empty()) spec.filter_model = d.filter_model;
  p.criterion = d.criterion;
  if (p.file.criterion) {
    if (!d.given.count("max-overshoot"))
      p.criterion.max_overshoot = p.file.criterion->max_overshoot;
    if (!d.given.count("min-settled")) p.criterion.min_settled = p.file.criterion->min_settled;
  }
}

// A plant point with axes applied: the edited task and model texts; an edited model is written
// under <out>/models (named by its content) and must load.
Result<PlantTask> MakePlantTask(const PreparedSweep& p, const SweepDefinition& d, size_t i,
                                const PlantPoint& pt, const std::string& task_text,
                                const std::string& model_text) {
  const std::string where = "sweep file '" + d.sweep_file + "'";
  std::string label = where + ": plant point " + std::to_string(i);
  for (const auto& [name, v] : pt.values) label += fmt::format(" {}={:g}", name, v);
  auto in = ApplyPlantPoint(task_text, model_text, p.file.axes, pt, where);
  if (!in.ok()) return in.failure();
  PlantTask pl;
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
    const fs::path dir = fs::path(d.out) / "models";
    std::error_code ec;
    fs::create_directories(dir, ec);
    const fs::path file =
        fs::absolute(dir / (fs::path(p.task.model_path).stem().string() + "_" + h.Hex() + ".xml"));
    if (!fs::exists(file, ec)) {
      RECRUIT_TRY(WriteFileAtomically(file.string(), in->model_text));
      auto m = LoadModel(file.string());
      if (!m.ok()) {
        std::error_code ignore;
        fs::remove(file, ignore);
        return m.failure().In(label + ": the edited model does not load: ");
      }
    }
    auto doc = nlohmann::json::parse(text);
    doc["model"] = file.string();
    text = doc.dump(1);
  }
  auto t = sim::Task::FromJsonText(text, p.task_path);
  if (!t.ok()) return t.failure().In(label + ": ");
  pl.task = std::move(t).value();
  return pl;
}

std::string Describe(const PreparedSweep& p) {
  std::string axes;
  for (const auto& ax : p.file.axes) axes += fmt::format(" x {} ({})", ax.name, ax.path);
  const char* sampling[] = {"grid", "Latin-hypercube sample", "Sobol sample"};
  const SweepSpec& spec = p.spec;
  return fmt::format(
      "Swept: {} plant point{} ({}{}) x dT {{{}}} x lambda {{{}}} x estimator {{{}}} x {} seeds "
      "= {} runs of {:g} s.",
      p.plant.size(), p.plant.size() == 1 ? "" : "s",
      p.file.axes.empty() ? "the task as given" : sampling[static_cast<int>(p.file.sampling)], axes,
      fmt::join(spec.dTs, ", "), fmt::join(spec.lambdas, ", "), fmt::join(spec.estimators, ", "),
      spec.seeds, p.grid.size(), spec.duration ? *spec.duration : p.task.duration);
}

// sweep.json: the folder holds one sweep (or one shard of it); its id must match to resume.
// Which runs can be reused is decided per run by its input hash.
Status CheckOrWriteId(const PreparedSweep& p, const SweepDefinition& d, const std::string& shard) {
  const std::string id_path = (fs::path(d.out) / "sweep.json").string();
  nlohmann::json id = {{"task", fs::absolute(p.task_path).lexically_normal().string()},
                       {"duration", p.spec.duration ? *p.spec.duration : p.task.duration},
                       {"filter_model", d.filter_model}};
  if (!d.sweep_file.empty()) id["sweep"] = fs::absolute(d.sweep_file).lexically_normal().string();
  if (!shard.empty()) id["shard"] = shard;
  std::error_code ec;  // a path the system refuses fails below, when the sweep writes it
  if (fs::exists(id_path, ec)) {
    auto old = LoadJsonFile(id_path);
    if (!old.ok()) return old.failure();
    if (*old != id) {
      return Error{
          "'" + ShortText(d.out) + "' holds another sweep (" + id_path + "); use another --out",
          ErrorCode::kUsage};
    }
    return Status::Ok();
  }
  return WriteFileAtomically(id_path, id.dump(2) + "\n");
}

}  // namespace

Result<PreparedSweep> Prepare(const SweepDefinition& d) {
  PreparedSweep p;
  if (!d.sweep_file.empty()) {
    auto f = SweepFile::FromFile(d.sweep_file);
    if (!f.ok()) return f.failure();
    p.file = std::move(f).value();
  }
  p.task_path = d.given.count("task") || p.file.task.empty() ? d.task : p.file.task;
  if (p.task_path.empty()) {
    return Error{"no task: give --task or \"task\" in the sweep file", ErrorCode::kUsage};
  }
  auto task_text = ReadFile(p.task_path);
  if (!task_text.ok()) return task_text.failure();
  auto task = sim::Task::FromJsonText(*task_text, p.task_path);
  if (!task.ok()) return task.failure();
  p.task = std::move(task).value();
  ResolveOptions(d, p);

  auto points = PlantPoints(p.file);
  if (!points.ok()) return points.failure();
  p.spec.plant = p.file.axes.empty() ? std::vector<PlantPoint>{} : *points;

  // Each plant point: apply it and parse the task, so a bad path or value fails now, naming the
  // axis and value.
  std::string model_text;
  if (!p.file.axes.empty()) {
    auto m = ReadFile(p.task.model_path);
    if (!m.ok()) return m.failure();
    model_text = *m;
  }
  for (size_t i = 0; i < points->size(); ++i) {
    if (p.file.axes.empty()) {
      PlantTask pl;
      pl.task = p.task;
      pl.task_text = *task_text;
      pl.model_text = ContentOf(p.task.model_path);
      p.plant.push_back(std::move(pl));
      continue;
    }
    auto pl = MakePlantTask(p, d, i, (*points)[i], *task_text, model_text);
    if (!pl.ok()) return pl.failure();
    p.plant.push_back(std::move(pl).value());
  }
  auto grid = ExpandGrid(p.spec);
  if (!grid.ok()) return grid.failure();
  p.grid = std::move(grid).value();
  std::map<std::string, std::string> contents;
  for (auto& g : p.grid) g.input_hash = RunInputHash(p.plant[g.plant], p.spec, g, contents);
  p.description = Describe(p);
  return p;
}

std::string InputHash(const PreparedSweep& p, const SweepRun& run) {
  std::map<std::string, std::string> contents;
  return RunInputHash(p.plant.at(run.plant), p.spec, run, contents);
}

Result<FileLock> OpenOutput(const PreparedSweep& p, const SweepDefinition& d) {
  // The outputs must not replace the inputs (a task file kept in the output folder).
  for (const char* name :
       {"sweep.json", "table.csv", "table.md", "stability.dat", "stability.png", "sweep.lock",
        "report.md", "report.html", "shard.json", "progress.log"}) {
    Status s = CheckNotAnInput((fs::path(d.out) / name).string(), "output",
                               {{"--task", p.task_path},
                                {"--sweep", d.sweep_file},
                                {"--filter-model", d.filter_model},
                                {"the task's model", p.task.model_path}});
    RECRUIT_TRY(s);
  }
  std::error_code ec;
  fs::create_directories(d.out, ec);
  if (ec) return IoError("cannot create --out '" + ShortText(d.out) + "': " + ec.message());
  auto lock = FileLock::TryLock((fs::path(d.out) / "sweep.lock").string());
  return lock;  // a folder another sweep holds is an I/O failure (FileLock says so)
}

Status WriteReports(const PreparedSweep& p, const std::vector<sim::RunSummary>& runs,
                    const std::string& out, const Drawing& draw) {
  const auto cells = Aggregate(p.grid, runs, p.criterion);
  RECRUIT_TRY(WriteTables(cells, p.criterion, out, p.task.name));
  if (p.file.axes.empty()) {  // the dT x lambda map, as `recruit plot --stability-map` draws it
    const plot::PlotOptions map =
        StabilityMapOptions(out, p.task.name, static_cast<int>(p.spec.estimators.size()));
    RECRUIT_TRY(draw.stability_map(map));
  }
  ReportInput in{p.task.name, p.description, p.criterion, cells, {}, {}, {}};
  in.seed_reasons = SeedReasonsMarkdown(p.grid, runs, p.criterion);
  in.unit = p.task.tracked == sim::Tracked::kForce ? "N" : "rad";
  // The output-only loop's latency bound needs each plant point's force latency (one open-loop
  // step of its model, ~0.1 s each); a point whose model cannot do it gets none (NaN).
  if (std::find(p.spec.estimators.begin(), p.spec.estimators.end(), "output") !=
      p.spec.estimators.end()) {
    in.latency.assign(p.plant.size(), std::nan(""));
    tbb::parallel_for(size_t{0}, p.plant.size(), [&](size_t i) {
      auto tau = ForceLatency(p.plant[i].task);
      if (tau.ok()) in.latency[i] = *tau;
    });
  }
  return WriteReport(in, out, draw.figure);
}

Result<SweepOutcome> Run(const PreparedSweep& p, const SweepDefinition& d, const std::string& shard,
                         int threads, const RunHooks& hooks, const Drawing& draw) {
  int shard_k = 1, shard_n = 1;
  if (!shard.empty()) {
    auto s = ParseShard(shard);
    if (!s.ok()) return s.failure();
    std::tie(shard_k, shard_n) = *s;
  }
  const std::vector<SweepRun> todo = shard.empty() ? p.grid : ShardOf(p.grid, shard_k, shard_n);
  // One sweep per folder at a time: the lock is held until this returns.
  auto lock = OpenOutput(p, d);
  if (!lock.ok()) return lock.failure();
  RECRUIT_TRY(CheckOrWriteId(p, d, shard));
  if (hooks.starting) hooks.starting(static_cast<int>(todo.size()));
  const SweepSpec& spec = p.spec;
  auto run = [&p, &spec](const SweepRun& g) {
    return sim::RunTask(p.plant[g.plant].task, RunOptionsFor(g, spec));
  };
  auto outcome = RunSweep(todo, d.out, run, threads, hooks.progress);
  if (!outcome.ok()) {
    return Error{outcome.error() + " (finished runs are kept; run again to resume)",
                 outcome.code()};
  }
  if (!shard.empty()) {
    // The shard's manifest: merge checks it belongs to the same sweep.
    nlohmann::json m = {
        {"sweep_id", SweepId(p.grid)}, {"shard", shard_k}, {"of", shard_n}, {"runs", todo.size()}};
    RECRUIT_TRY(WriteFileAtomically((fs::path(d.out) / "shard.json").string(), m.dump(2) + "\n"));
    return outcome;
  }
  RECRUIT_TRY(WriteReports(p, outcome->runs, d.out, draw));
  return outcome;
}

Result<MergeOutcome> Merge(const PreparedSweep& p, const SweepDefinition& d,
                           const std::vector<std::string>& shard_dirs, const Drawing& draw,
                           const std::function<void(const std::string&)>& note) {
  const std::string id = SweepId(p.grid);
  std::map<int, fs::path> dirs;
  int n = 0;
  for (const auto& dir : shard_dirs) {
    const std::string mpath = (fs::path(dir) / "shard.json").string();
    std::error_code ec;
    if (!fs::exists(mpath, ec)) {
      if (note) note("'" + dir + "' has no shard.json (unfinished shard)");
      continue;
    }
    auto m = LoadJsonFile(mpath);
    if (!m.ok()) return m.failure();
    if (!m->is_object() || !m->contains("sweep_id") || !m->contains("shard") ||
        !m->contains("of") || !(*m)["shard"].is_number_integer() ||
        !(*m)["of"].is_number_integer()) {
      return Error{mpath + ": not a shard manifest"};
    }
    if ((*m)["sweep_id"] != id) {
      return Error{mpath +
                   ": a shard of another sweep (other task, axes, options or build; its "
                   "sweep_id " +
                   (*m)["sweep_id"].dump() + ", this sweep's \"" + id + "\")"};
    }
    const int k = (*m)["shard"], of = (*m)["of"];
    if (n != 0 && of != n) {
      return Error{fmt::format("{}: shard {}/{} among shards of {}", mpath, k, of, n)};
    }
    n = of;
    if (dirs.count(k)) {
      return Error{fmt::format("shard {} given twice ('{}', '{}')", k, dirs[k].string(), dir),
                   ErrorCode::kUsage};
    }
    dirs[k] = dir;
  }
  if (n == 0) return Error{"no finished shard among the folders given"};
  std::vector<int> missing;
  for (int k = 1; k <= n; ++k) {
    if (!dirs.count(k)) missing.push_back(k);
  }
  auto lock = OpenOutput(p, d);
  if (!lock.ok()) return lock.failure();
  const fs::path runs_dir = fs::path(d.out) / "runs";
  std::error_code ec;
  fs::create_directories(runs_dir, ec);
  if (ec) return IoError("cannot create '" + runs_dir.string() + "': " + ec.message());
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
    if (!text.ok()) return text.failure();
    RECRUIT_TRY(WriteFileAtomically((runs_dir / (g.Key() + ".json")).string(), *text));
  }
  if (!incomplete.empty()) {
    return Error{
        fmt::format("shards {} of {} are missing or incomplete; rerun them (each resumes "
                    "its finished runs), e.g. sbatch --array={} scripts/slurm/"
                    "sweep_array.sh ..., then merge again",
                    fmt::join(incomplete, ","), n, fmt::join(incomplete, ","))};
  }
  // Every run is now recorded in `d.out`: RunSweep only reads them back.
  auto none = [](const SweepRun& g) -> Result<sim::RunSummary> {
    return Error{"run " + g.Key() + " missing after merge", ErrorCode::kInternal};  // a bug
  };
  auto outcome = RunSweep(p.grid, d.out, none, 1);
  if (!outcome.ok()) return outcome.failure();
  RECRUIT_TRY(WriteReports(p, outcome->runs, d.out, draw));
  return MergeOutcome{n, std::move(outcome).value()};
}

}  // namespace recruit::sweep
