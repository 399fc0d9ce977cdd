#include "sweep/grid.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <map>
#include <mutex>
#include <set>

#include "common/atomic_file.h"
#include "common/content_hash.h"
#include "common/json_file.h"
#include "common/rng.h"
#include "control/sampling_period.h"

namespace recruit::sweep {
namespace fs = std::filesystem;
using nlohmann::json;
using sim::MetricsFromJson;
using sim::RunMetrics;
using sim::RunOptions;
using sim::RunSummary;
using sim::StepResponse;

std::string SweepRun::Key() const {
  std::string est;
  for (char c : estimator) est += std::isalnum(static_cast<unsigned char>(c)) ? c : '-';
  const std::string key = fmt::format("dT{:g}_l{:g}_{}_s{}", dT, lambda, est, seed_index);
  return plant_values.empty() ? key : fmt::format("p{:04d}_{}", plant, key);
}

RunOptions RunOptionsFor(const SweepRun& run, const SweepSpec& spec) {
  RunOptions o;
  o.estimator = run.estimator;
  o.dT = run.dT;
  o.lambda = run.lambda;
  o.seed = run.seed;
  o.duration = spec.duration;
  o.filter_model = spec.filter_model;
  o.identify_missing_models = spec.identify_missing_models;
  return o;
}

Result<std::vector<SweepRun>> ExpandGrid(const SweepSpec& spec) {
  // The axes are the sweep's options: a bad one is a usage error.
  const auto usage = [](std::string message) {
    return Error{std::move(message), ErrorCode::kUsage};
  };
  if (spec.dTs.empty()) return usage("sweep: no dT values (--dT)");
  if (spec.lambdas.empty()) return usage("sweep: no lambda values (--lambda)");
  if (spec.estimators.empty()) return usage("sweep: no estimators (--estimator)");
  if (spec.seeds < 1) return usage("sweep: --seeds must be >= 1");
  for (double x : spec.dTs) {
    if (Status s = control::CheckDT(x, "sweep"); !s.ok()) return usage(s.error());
  }
  for (double x : spec.lambdas) {
    if (!(x > 0 && x <= 1)) return usage(fmt::format("sweep: lambda {} must be in (0, 1]", x));
  }
  const std::vector<PlantPoint> plant =
      spec.plant.empty() ? std::vector<PlantPoint>{PlantPoint{}} : spec.plant;
  std::vector<SweepRun> grid;
  for (size_t p = 0; p < plant.size(); ++p) {
    for (double dT : spec.dTs) {
      for (double lambda : spec.lambdas) {
        for (const auto& est : spec.estimators) {
          for (int s = 0; s < spec.seeds; ++s) {
            SweepRun r;
            r.index = static_cast<int>(grid.size());
            r.plant = static_cast<int>(p);
            r.plant_values = plant[p].values;
            r.dT = dT;
            r.lambda = lambda;
            r.estimator = est;
            r.seed_index = s;
            r.seed = Rng::DeriveSeed(spec.base_seed, static_cast<std::uint64_t>(s));
            grid.push_back(r);
          }
        }
      }
    }
  }
  std::set<std::string> keys;
  for (const auto& r : grid) {
    if (!keys.insert(r.Key()).second) return Error{"sweep: grid point repeated: " + r.Key()};
  }
  return grid;
}

std::vector<SweepRun> ShardOf(const std::vector<SweepRun>& grid, int k, int n) {
  std::vector<SweepRun> out;
  for (const auto& r : grid) {
    if (r.index % n == k - 1) out.push_back(r);
  }
  return out;
}

Result<std::pair<int, int>> ParseShard(const std::string& text) {
  const auto slash = text.find('/');
  int k = 0, n = 0;
  try {
    size_t used = 0;
    if (slash == std::string::npos) throw std::invalid_argument("no slash");
    k = std::stoi(text.substr(0, slash), &used);
    if (used != slash) throw std::invalid_argument("K");
    n = std::stoi(text.substr(slash + 1), &used);
    if (used != text.size() - slash - 1) throw std::invalid_argument("N");
  } catch (const std::exception&) {
    return Error{"--shard '" + text + "': must be K/N with whole numbers, e.g. 3/8",
                 ErrorCode::kUsage};
  }
  if (n < 1 || n > 100000 || k < 1 || k > n) {
    return Error{"--shard '" + text + "': need 1 <= K <= N <= 100000", ErrorCode::kUsage};
  }
  return std::make_pair(k, n);
}

std::string SweepId(const std::vector<SweepRun>& grid) {
  ContentHash h;
  for (const auto& r : grid) h.Add(r.Key()).Add(r.input_hash);
  return h.Hex();
}

Result<RunSummary> RunSummaryFromJson(const json& j) {
  try {
    RunSummary s;
    s.task = j.at("task").get<std::string>();
    s.estimator = j.at("estimator").get<std::string>();
    s.dT = j.at("dT").get<double>();
    s.lambda = j.at("lambda").get<double>();
    s.seed = j.at("seed").get<std::uint64_t>();
    s.duration = j.at("duration").get<double>();
    s.unit = j.at("unit").get<std::string>();
    s.physics_steps = j.at("physics_steps").get<long>();
    s.control_instants = j.at("control_instants").get<long>();
    s.wall_seconds = j.at("wall_seconds").get<double>();
    s.metrics = MetricsFromJson(j.at("metrics"));
    for (const json& st : j.at("steps")) {
      StepResponse sr;
      sr.step = {st.at("time"), st.at("from"), st.at("to"), st.at("end")};
      sr.overshoot = st.at("overshoot");
      sr.settling_time = st.at("settling_time");
      sr.settled = st.at("settled");
      s.steps.push_back(sr);
    }
    // The wires' peaks against their limits and the warnings (absent in older records).
    for (const json& b : j.value("bundles", json::array())) {
      sim::BundleSummary bs;
      bs.actuator = b.at("actuator").get<std::string>();
      bs.estimator_rmse = b.at("estimator_rmse").get<double>();
      bs.mean_nees = b.at("mean_nees").is_number() ? b.at("mean_nees").get<double>() : std::nan("");
      bs.estimator_within3 = b.at("estimator_within3").get<double>();
      bs.peak_temperature = b.at("peak_temperature").get<double>();
      bs.peak_wire_stress = b.at("peak_wire_stress").get<double>();
      bs.max_temperature = b.at("max_temperature").get<double>();
      bs.max_wire_stress = b.at("max_wire_stress").get<double>();
      s.bundles.push_back(bs);
    }
    s.warnings = j.value("warnings", std::vector<std::string>{});
    return s;
  } catch (const json::exception& e) {
    return Error{std::string("run record: ") + e.what()};
  }
}

Result<SweepOutcome> RunSweep(const std::vector<SweepRun>& grid, const std::string& out_dir,
                              const SweepRunFn& run, int threads,
                              const std::function<void(int, int)>& progress) {
  const fs::path runs_dir = fs::path(out_dir) / "runs";
  std::error_code ec;
  fs::create_directories(runs_dir, ec);
  if (ec)
    return Error{"sweep: cannot create '" + runs_dir.string() + "': " + ec.message(),
                 ErrorCode::kIo};

  SweepOutcome outcome;
  outcome.runs.resize(grid.size());
  std::vector<size_t> todo;
  for (size_t i = 0; i < grid.size(); ++i) {
    const fs::path p = runs_dir / (grid[i].Key() + ".json");
    bool reused = false;
    std::error_code ec;  // an unreadable record is not reused
    if (fs::exists(p, ec)) {
      auto j = LoadJsonFile(p.string());
      if (j.ok() && j->is_object()) {
        auto s = RunSummaryFromJson(*j);
        // A record counts only if it is the same grid point (same seed, dT, lambda, estimator)
        // made from the same inputs (same input hash).
        const auto h = j->find("input_hash");
        const std::string hash = h != j->end() && h->is_string() ? h->get<std::string>() : "";
        if (s.ok() && s->seed == grid[i].seed && s->dT == grid[i].dT &&
            s->lambda == grid[i].lambda && s->estimator == grid[i].estimator &&
            hash == grid[i].input_hash) {
          outcome.runs[i] = std::move(s).value();
          reused = true;
        }
      }
    }
    if (reused) {
      ++outcome.reused;
    } else {
      todo.push_back(i);
    }
  }

  // One line per finished run, appended and flushed so `tail -f progress.log` follows the sweep.
  std::FILE* log = std::fopen((fs::path(out_dir) / "progress.log").c_str(), "a");
  const auto t0 = std::chrono::steady_clock::now();
  std::mutex mu;
  Error first_error;
  std::atomic<bool> failed{false};
  int done = outcome.reused;
  const int total = static_cast<int>(grid.size());
  auto body = [&](size_t t) {
    if (failed) return;
    const SweepRun& g = grid[todo[t]];
    auto s = run(g);
    Status st;
    if (s.ok()) {
      nlohmann::json record = s->ToJson();
      record["input_hash"] = g.input_hash;
      st = WriteFileAtomically((runs_dir / (g.Key() + ".json")).string(), record.dump(1));
    } else {
      st = Error{"sweep run " + g.Key() + ": " + s.error(), s.code()};
    }
    std::lock_guard<std::mutex> lock(mu);
    if (!st.ok()) {
      if (!failed.exchange(true)) first_error = st.failure();
      return;
    }
    outcome.runs[todo[t]] = std::move(s).value();
    ++outcome.executed;
    ++done;
    if (log) {
      const RunSummary& r = outcome.runs[todo[t]];
      const std::time_t now = std::time(nullptr);
      char stamp[32];
      std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
      const double elapsed =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const double eta = elapsed / outcome.executed * (total - done);
      std::fprintf(log,
                   "%s %d/%d %s rmse=%.4g overshoot=%.4f settled=%.2f est_rmse=%.3g wall=%.2fs "
                   "eta=%.0fs\n",
                   stamp, done, total, g.Key().c_str(), r.metrics.tracking_rmse,
                   r.metrics.overshoot, r.metrics.settled_fraction, r.metrics.estimator_rmse,
                   r.wall_seconds, eta);
      std::fflush(log);
    }
    if (progress) progress(done, total);
  };
  const int n = threads > 0 ? threads : tbb::this_task_arena::max_concurrency();
  tbb::task_arena arena(n);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, todo.size(), 1),
                      [&](const tbb::blocked_range<size_t>& r) {
                        for (size_t t = r.begin(); t != r.end(); ++t) body(t);
                      });
  });
  if (log) std::fclose(log);
  if (failed) return first_error;
  return outcome;
}

}  // namespace recruit::sweep
