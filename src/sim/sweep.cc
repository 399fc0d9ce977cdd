#include "sim/sweep.h"

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

namespace recruit::sim {
namespace fs = std::filesystem;
using nlohmann::json;

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
  if (spec.dTs.empty()) return Error{"sweep: no dT values (--dT)"};
  if (spec.lambdas.empty()) return Error{"sweep: no lambda values (--lambda)"};
  if (spec.estimators.empty()) return Error{"sweep: no estimators (--estimator)"};
  if (spec.seeds < 1) return Error{"sweep: --seeds must be >= 1"};
  for (double x : spec.dTs) {
    if (!(x > 0) || !std::isfinite(x)) return Error{fmt::format("sweep: dT {} must be > 0", x)};
  }
  for (double x : spec.lambdas) {
    if (!(x > 0 && x <= 1)) return Error{fmt::format("sweep: lambda {} must be in (0, 1]", x)};
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
    return Error{"--shard '" + text + "': must be K/N with whole numbers, e.g. 3/8"};
  }
  if (n < 1 || n > 100000 || k < 1 || k > n) {
    return Error{"--shard '" + text + "': need 1 <= K <= N <= 100000"};
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

namespace {

double Mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0 : s / v.size();
}
double Sd(const std::vector<double>& v) {
  if (v.size() < 2) return 0;
  const double m = Mean(v);
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / (v.size() - 1));
}

// >= 0 iff the criterion is met: min(overshoot limit - overshoot, settled - required settled).
double Margin(const TrackingCriterion& criterion, double overshoot, double settled_fraction) {
  return std::min(criterion.max_overshoot - overshoot, settled_fraction - criterion.min_settled);
}

}  // namespace

std::vector<CellStats> Aggregate(const std::vector<RunSummary>& runs,
                                 const TrackingCriterion& criterion) {
  std::vector<SweepRun> grid(runs.size());
  return Aggregate(grid, runs, criterion);
}

std::vector<CellStats> Aggregate(const std::vector<SweepRun>& grid,
                                 const std::vector<RunSummary>& runs,
                                 const TrackingCriterion& criterion) {
  std::vector<CellStats> cells;
  using Key = std::tuple<int, double, double, std::string>;
  std::map<Key, std::vector<const RunSummary*>> groups;
  std::map<Key, const SweepRun*> first;
  std::vector<Key> order;
  for (size_t i = 0; i < runs.size(); ++i) {
    const RunSummary& r = runs[i];
    auto key = std::make_tuple(grid.at(i).plant, r.dT, r.lambda, r.estimator);
    if (!groups.count(key)) {
      order.push_back(key);
      first[key] = &grid[i];
    }
    groups[key].push_back(&r);
  }
  for (const auto& key : order) {
    const auto& g = groups[key];
    CellStats c;
    std::tie(c.plant, c.dT, c.lambda, c.estimator) = key;
    c.plant_values = first[key]->plant_values;
    c.seeds = static_cast<int>(g.size());
    std::vector<double> margins;
    for (const RunSummary* r : g) {
      margins.push_back(Margin(criterion, r->metrics.overshoot, r->metrics.settled_fraction));
      if (margins.back() >= 0) ++c.seeds_meeting;
    }
    for (size_t k = 0; k < kMetricCount; ++k) {
      const MetricField& f = kMetricFields[k];
      std::vector<double> v;
      for (const RunSummary* r : g) {
        const double x = MetricValue(r->metrics, f);
        if (!f.may_be_nan || std::isfinite(x)) v.push_back(x);
      }
      c.mean[k] = f.may_be_nan && v.empty() ? std::nan("") : Mean(v);
      c.sd[k] = Sd(v);
    }
    c.margin =
        Margin(criterion, c.Mean(&RunMetrics::overshoot), c.Mean(&RunMetrics::settled_fraction));
    c.meets = c.margin >= 0;
    c.margin_se = Sd(margins) / std::sqrt(static_cast<double>(margins.size()));
    cells.push_back(c);
  }
  return cells;
}

std::vector<std::string> CellColumns() {
  std::vector<std::string> out{"dT", "lambda", "estimator", "seeds"};
  for (std::string& name : CellMetricColumns()) out.push_back(std::move(name));
  out.push_back("meets_criterion");
  out.push_back("margin");
  return out;
}

std::vector<double> CellMetricValues(const CellStats& c) {
  std::vector<double> out;
  for (size_t k = 0; k < kMetricCount; ++k) {
    if (!kMetricFields[k].cell_mean) continue;
    out.push_back(c.mean[k]);
    if (kMetricFields[k].cell_sd) out.push_back(c.sd[k]);
  }
  return out;
}

// Numbers: every value of table.csv, and the grid coordinates (plant values, dT, lambda) in
// table.md, are written as "{}" writes them: the shortest text that reads back as the same double
// (0.29, not 0.28999999999999998). table.md rounds its measured statistics for reading; table.csv
// holds them exactly.
Status WriteSweepReport(const std::vector<CellStats>& cells, const TrackingCriterion& criterion,
                        const std::string& out_dir, const std::string& title) {
  const fs::path dir(out_dir);
  // Plant axes, when the sweep has them, lead each row (from the first cell: all share them).
  const auto& axes =
      cells.empty() ? std::vector<std::pair<std::string, double>>{} : cells.front().plant_values;
  std::string plant_head, plant_md_head, plant_md_rule;
  for (const auto& [name, v] : axes) {
    plant_head += name + ",";
    plant_md_head += "| " + name + " ";
    plant_md_rule += "|---";
  }
  if (!axes.empty()) {
    plant_head = "plant," + plant_head;
    plant_md_head = "| plant " + plant_md_head;
    plant_md_rule = "|---" + plant_md_rule;
  }
  auto plant_cols = [](const CellStats& c, bool md) {
    if (c.plant_values.empty()) return std::string();
    std::string out = md ? fmt::format("| {} ", c.plant) : fmt::format("{},", c.plant);
    for (const auto& [name, v] : c.plant_values) {
      out += md ? fmt::format("| {} ", v) : fmt::format("{},", v);
    }
    return out;
  };
  std::string csv = plant_head;
  for (const std::string& name : CellColumns()) csv += name + ",";
  csv.back() = '\n';
  std::string md = fmt::format(
      "# Sweep: {}\n\nCriterion: mean step overshoot <= {:.0f} % and at least {:.0f} % of "
      "steps settled within the 10 % band, over all seeds of a cell. Margin = min(overshoot "
      "limit - overshoot, settled fraction - required fraction).\n\n"
      "{}| dT (s) | lambda | estimator | seeds | overshoot (%) | settling (s) | settled (%) | "
      "RMSE | oscillation | switching (1/unit/s) | est. RMSE (units) | NEES | within 3 (%) | "
      "meets | margin |\n{}|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
      title, 100 * criterion.max_overshoot, 100 * criterion.min_settled, plant_md_head,
      plant_md_rule);
  for (const auto& c : cells) {
    csv += plant_cols(c, false) + fmt::format("{},{},{},{},", c.dT, c.lambda, c.estimator, c.seeds);
    for (double x : CellMetricValues(c)) csv += fmt::format("{},", x);
    csv += fmt::format("{},{}\n", c.meets ? 1 : 0, c.margin);
    md += (c.plant_values.empty() ? "" : plant_cols(c, true)) +
          fmt::format(
              "| {} | {} | {} | {} | {:.1f} ± {:.1f} | {:.2f} | {:.0f} | {:.3g} | {:.3f} | "
              "{:.4f} "
              "| {:.2f} | {:.2f} | {:.0f} | {} | {:+.3f} |\n",
              c.dT, c.lambda, c.estimator, c.seeds, 100 * c.Mean(&RunMetrics::overshoot),
              100 * c.Sd(&RunMetrics::overshoot), c.Mean(&RunMetrics::settling_time),
              100 * c.Mean(&RunMetrics::settled_fraction), c.Mean(&RunMetrics::tracking_rmse),
              c.Mean(&RunMetrics::oscillation), c.Mean(&RunMetrics::switching_rate),
              c.Mean(&RunMetrics::estimator_rmse), c.Mean(&RunMetrics::mean_nees),
              100 * c.Mean(&RunMetrics::estimator_within3), c.meets ? "yes" : "no", c.margin);
  }

  // Shortest sampling period meeting the criterion, per plant point, estimator and lambda.
  std::string shortest = fmt::format(
      "\n## Shortest sampling period meeting the criterion\n\n"
      "{}| estimator | lambda | shortest dT (s) | margin | next shorter dT tried "
      "|\n{}|---|---|---|---|---|\n",
      plant_md_head, plant_md_rule);
  std::vector<std::tuple<int, std::string, double>> el;
  for (const auto& c : cells) {
    auto key = std::make_tuple(c.plant, c.estimator, c.lambda);
    if (std::find(el.begin(), el.end(), key) == el.end()) el.push_back(key);
  }
  for (const auto& [plant, est, lambda] : el) {
    std::vector<const CellStats*> col;
    for (const auto& c : cells) {
      if (c.plant == plant && c.estimator == est && c.lambda == lambda) col.push_back(&c);
    }
    std::sort(col.begin(), col.end(), [](auto* a, auto* b) { return a->dT < b->dT; });
    const std::string lead = plant_cols(*col.front(), true);
    // The shortest dT tried that meets it (a long dT can fail too: too slow to settle).
    int best = -1;
    for (int i = 0; i < static_cast<int>(col.size()) && best < 0; ++i) {
      if (col[i]->meets) best = i;
    }
    if (best < 0) {
      shortest += lead + fmt::format("| {} | {} | none of the dT tried | - | - |\n", est, lambda);
    } else {
      const std::string next =
          best > 0 ? fmt::format("{} (margin {:+.3f})", col[best - 1]->dT, col[best - 1]->margin)
                   : std::string("none shorter tried");
      shortest += lead + fmt::format("| {} | {} | {} | {:+.3f} | {} |\n", est, lambda,
                                     col[best]->dT, col[best]->margin, next);
    }
  }
  md += shortest;

  Status s = WriteFileAtomically((dir / "table.csv").string(), csv);
  if (!s.ok()) return s;
  s = WriteFileAtomically((dir / "table.md").string(), md);
  if (!s.ok()) return s;
  // With plant axes the dT x lambda map would overlay plant points: the sweep report
  // (src/sweep/sweep_report.h) draws per-plant-point figures instead.
  if (!axes.empty()) return Status::Ok();

  // Stability map: one panel per estimator, dT (log) x lambda, colour = mean overshoot,
  // a ring around cells that meet the criterion.
  std::vector<std::string> ests;
  for (const auto& c : cells) {
    if (std::find(ests.begin(), ests.end(), c.estimator) == ests.end()) ests.push_back(c.estimator);
  }
  std::string dat;
  for (const auto& e : ests) {
    dat += "# estimator " + e + "\n# dT lambda overshoot_percent meets\n";
    for (const auto& c : cells) {
      if (c.estimator == e) {
        dat += fmt::format("{} {} {:.4f} {}\n", c.dT, c.lambda,
                           100 * c.Mean(&RunMetrics::overshoot), c.meets ? 1 : 0);
      }
    }
    dat += "\n\n";
  }
  s = WriteFileAtomically((dir / "stability.dat").string(), dat);
  if (!s.ok()) return s;
  // stability.png is drawn from it by `recruit plot --stability-map`'s code
  // (sweep::StabilityMapOptions), in the plot module `recruit sweep` opens.
  return Status::Ok();
}

}  // namespace recruit::sim
