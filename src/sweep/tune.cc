#include "sweep/tune.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <tuple>

#include "common/atomic_file.h"
#include "common/mujoco_load.h"
#include "common/rng.h"

namespace recruit::sweep {
namespace {

namespace fs = std::filesystem;

double Percentile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const double pos = q * (v.size() - 1);
  const size_t i = static_cast<size_t>(pos);
  return i + 1 < v.size() ? v[i] + (pos - i) * (v[i + 1] - v[i]) : v.back();
}

// One search: a plant point, estimator and lambda, with its runs by lattice index and seed.
struct Column {
  int plant = 0;
  std::string estimator;
  double lambda = 0;
  std::map<int, std::vector<sim::RunSummary>> runs;
  std::vector<sim::RunSummary> check;  // the recommended dT on new seeds
};

Tallies TalliesOf(const Column& c, const TuneCriterion& crit) {
  Tallies t;
  for (const auto& [k, runs] : c.runs) {
    Tally& tally = t[k];
    for (const auto& r : runs) {
      ++tally.seeds;
      tally.meeting += CheckSeed(r, crit).meets();
    }
  }
  return t;
}

// Runs each search's recommended dT on d.check_seeds new seeds into <out>/check.
Status CheckOnNewSeeds(const PreparedSweep& p, const TuneDefinition& d, const DtLattice& lattice,
                       int threads, const TuneHooks& hooks, std::vector<Column>& columns,
                       TuneOutcome& out) {
  if (d.check_seeds <= 0) return Status::Ok();
  std::vector<SweepRun> batch;
  std::vector<size_t> where;
  for (size_t c = 0; c < columns.size(); ++c) {
    const Window w = FindWindow(TalliesOf(columns[c], d.criterion), d.settings, lattice);
    if (!w.found) continue;
    for (int s = 0; s < d.check_seeds; ++s) {
      SweepRun r;
      r.index = static_cast<int>(batch.size());
      r.plant = columns[c].plant;
      r.plant_values = p.spec.plant.empty() ? std::vector<std::pair<std::string, double>>{}
                                            : p.spec.plant[r.plant].values;
      r.dT = lattice.dT(w.recommended);
      r.lambda = columns[c].lambda;
      r.estimator = columns[c].estimator;
      r.seed_index = s;
      r.seed = Rng::DeriveSeed(d.check_base_seed, static_cast<std::uint64_t>(s));
      r.input_hash = InputHash(p, r);
      batch.push_back(r);
      where.push_back(c);
    }
  }
  if (batch.empty()) return Status::Ok();
  if (hooks.round) hooks.round(out.rounds + 1, static_cast<int>(batch.size()));
  auto run = [&p](const SweepRun& g) {
    return sim::RunTask(p.plant[g.plant].task, RunOptionsFor(g, p.spec));
  };
  auto done =
      RunSweep(batch, (fs::path(d.sweep.out) / "check").string(), run, threads, hooks.progress);
  if (!done.ok()) {
    return Error{done.error() + " (finished runs are kept; run again to resume)", done.code()};
  }
  out.check_runs = static_cast<int>(batch.size());
  for (size_t i = 0; i < batch.size(); ++i) {
    columns[where[i]].check.push_back(std::move(done->runs[i]));
  }
  return Status::Ok();
}

}  // namespace

SeedCheck CheckSeed(const sim::RunSummary& run, const TuneCriterion& c) {
  SeedCheck s;
  const sim::RunMetrics& m = run.metrics;
  s.overshoot = m.overshoot > c.tracking.max_overshoot;
  s.settling = m.settled_fraction < c.tracking.min_settled;
  s.worst_step = m.max_overshoot > c.max_step_overshoot;
  s.limits = run.PastDatasheetLimits();
  return s;
}

DtRow SummarizeDt(double dT, const std::vector<sim::RunSummary>& runs, const TuneCriterion& c,
                  const TuneSettings& s) {
  DtRow row;
  row.dT = dT;
  std::vector<double> steps;
  double settled = 0, rmse = 0, nees = 0;
  int nees_n = 0;
  for (const auto& r : runs) {
    const SeedCheck ch = CheckSeed(r, c);
    ++row.seeds;
    row.meeting += ch.meets();
    row.fail_overshoot += ch.overshoot;
    row.fail_settling += ch.settling;
    row.fail_worst_step += ch.worst_step;
    row.fail_limits += ch.limits;
    for (const auto& st : r.steps) steps.push_back(st.overshoot);
    for (const auto& w : r.warnings) {
      if (w.find("exceeds the limit") != std::string::npos) continue;  // counted as limits
      auto it = std::find_if(row.warnings.begin(), row.warnings.end(),
                             [&w](const auto& x) { return x.first == w; });
      if (it == row.warnings.end()) {
        row.warnings.emplace_back(w, 1);
      } else {
        ++it->second;
      }
    }
    settled += r.metrics.settled_fraction;
    rmse += r.metrics.estimator_rmse;
    if (std::isfinite(r.metrics.mean_nees)) {
      nees += r.metrics.mean_nees;
      ++nees_n;
    }
    for (const auto& b : r.bundles) {
      if (b.max_temperature > 0) {
        row.worst_temperature_ratio =
            std::max(row.worst_temperature_ratio, b.peak_temperature / b.max_temperature);
      }
      if (b.max_wire_stress > 0) {
        row.worst_stress_ratio =
            std::max(row.worst_stress_ratio, b.peak_wire_stress / b.max_wire_stress);
      }
    }
  }
  const int n = std::max(1, row.seeds);
  row.fraction = WilsonInterval(row.meeting, row.seeds, NormalQuantile(s.confidence));
  row.verdict = Judge({row.seeds, row.meeting}, s);
  double sum = 0;
  for (double x : steps) sum += x;
  row.overshoot_mean = steps.empty() ? std::nan("") : sum / steps.size();
  row.overshoot_p95 = Percentile(steps, 0.95);
  row.overshoot_worst =
      steps.empty() ? std::nan("") : *std::max_element(steps.begin(), steps.end());
  row.settled_mean = settled / n;
  row.estimator_rmse = rmse / n;
  row.mean_nees = nees_n ? nees / nees_n : std::nan("");
  return row;
}

double PhysicsTimestep(const PreparedSweep& p) {
  if (p.task.timestep > 0) return p.task.timestep;
  auto m = LoadModel(p.task.model_path);
  return m.ok() ? (*m)->opt.timestep : 0;
}

Result<TuneOutcome> Tune(const PreparedSweep& p, const TuneDefinition& d, int threads,
                         const TuneHooks& hooks) {
  if (std::string why = CheckTuneSettings(d.settings); !why.empty()) {
    return Error{"tune: " + why, ErrorCode::kUsage};
  }
  if (d.check_seeds > 0 && d.check_base_seed == p.spec.base_seed) {
    return Error{fmt::format("tune: --check-base-seed {} is the search's --base-seed: the check "
                             "needs seeds the search never used",
                             d.check_base_seed),
                 ErrorCode::kUsage};
  }
  const DtLattice lattice(d.settings);
  auto lock = OpenOutput(p, d.sweep);
  if (!lock.ok()) return lock.failure();

  std::vector<Column> columns;
  if (d.shard_n < 1 || d.shard_k < 1 || d.shard_k > d.shard_n) {
    return Error{"tune: bad shard", ErrorCode::kUsage};
  }
  int search = 0;  // index of a search in plant point x lambda x estimator order
  for (size_t pl = 0; pl < p.plant.size(); ++pl) {
    for (double lambda : p.spec.lambdas) {
      for (const auto& est : p.spec.estimators) {
        if (search++ % d.shard_n == d.shard_k - 1) {
          columns.push_back({static_cast<int>(pl), est, lambda, {}, {}});
        }
      }
    }
  }
  const std::vector<PlantPoint> plant =
      p.spec.plant.empty() ? std::vector<PlantPoint>{PlantPoint{}} : p.spec.plant;
  TuneOutcome out;
  auto run = [&p](const SweepRun& g) {
    return sim::RunTask(p.plant[g.plant].task, RunOptionsFor(g, p.spec));
  };
  for (int round = 0; round < 1000; ++round) {
    // Every column's next requests, as sweep runs (seed indices not yet run there).
    std::vector<SweepRun> batch;
    std::vector<std::pair<size_t, int>> where;  // column, lattice index of each run
    for (size_t c = 0; c < columns.size(); ++c) {
      for (const Request& q : NextBatch(TalliesOf(columns[c], d.criterion), d.settings, lattice)) {
        const int have = static_cast<int>(columns[c].runs[q.index].size());
        for (int s = have; s < q.seeds; ++s) {
          SweepRun r;
          r.index = static_cast<int>(batch.size());
          r.plant = columns[c].plant;
          r.plant_values = plant[r.plant].values;
          r.dT = lattice.dT(q.index);
          r.lambda = columns[c].lambda;
          r.estimator = columns[c].estimator;
          r.seed_index = s;
          r.seed = Rng::DeriveSeed(p.spec.base_seed, static_cast<std::uint64_t>(s));
          r.input_hash = InputHash(p, r);
          batch.push_back(r);
          where.emplace_back(c, q.index);
        }
      }
    }
    if (batch.empty()) break;
    out.rounds = round + 1;
    if (hooks.round) hooks.round(round + 1, static_cast<int>(batch.size()));
    auto done = RunSweep(batch, d.sweep.out, run, threads, hooks.progress);
    if (!done.ok()) {
      return Error{done.error() + " (finished runs are kept; run again to resume)", done.code()};
    }
    out.executed += done->executed;
    out.reused += done->reused;
    // Runs come back in batch order, and a period's seeds in index order.
    for (size_t i = 0; i < batch.size(); ++i) {
      columns[where[i].first].runs[where[i].second].push_back(std::move(done->runs[i]));
    }
  }

  if (Status s = CheckOnNewSeeds(p, d, lattice, threads, hooks, columns, out); !s.ok()) {
    return s.failure();
  }
  out.shortest_hold = std::nan("");
  for (const Column& c : columns) {
    TuneColumn tc;
    tc.plant = c.plant;
    tc.plant_values = plant[c.plant].values;
    tc.estimator = c.estimator;
    tc.lambda = c.lambda;
    const Tallies t = TalliesOf(c, d.criterion);
    tc.window = FindWindow(t, d.settings, lattice);
    tc.lower_edge = tc.window.found ? EdgeEstimate(tc.window.lower, lattice) : std::nan("");
    tc.upper_edge = tc.window.found ? EdgeEstimate(tc.window.upper, lattice) : std::nan("");
    tc.recommended = tc.window.found ? lattice.dT(tc.window.recommended) : std::nan("");
    for (const auto& [k, runs] : c.runs) {
      tc.rows.push_back(SummarizeDt(lattice.dT(k), runs, d.criterion, d.settings));
      tc.runs += static_cast<int>(runs.size());
      tc.max_seeds_used = std::max(tc.max_seeds_used, static_cast<int>(runs.size()));
      for (const auto& r : runs) {
        for (const auto& st : r.steps) {
          const double hold = st.step.end - st.step.time;
          if (!(hold >= out.shortest_hold)) out.shortest_hold = hold;
        }
      }
    }
    if (c.check.size() > 0) {
      tc.check = SummarizeDt(tc.recommended, c.check, d.criterion, d.settings);
      tc.check_p = BinomialCdf(tc.check.meeting, tc.check.seeds, d.settings.level);
    }
    out.runs += tc.runs;
    out.grid_runs += static_cast<long>(lattice.size()) * tc.max_seeds_used;
    out.columns.push_back(std::move(tc));
  }
  return out;
}

}  // namespace recruit::sweep
