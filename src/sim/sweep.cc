#include "sim/sweep.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>
#include <set>

#include "common/atomic_file.h"
#include "common/json_file.h"
#include "common/rng.h"

namespace recruit::sim {
namespace fs = std::filesystem;
using nlohmann::json;

std::string SweepRun::Key() const {
  std::string est;
  for (char c : estimator) est += std::isalnum(static_cast<unsigned char>(c)) ? c : '-';
  return fmt::format("dT{:g}_l{:g}_{}_s{}", dT, lambda, est, seed_index);
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
  std::vector<SweepRun> grid;
  for (double dT : spec.dTs) {
    for (double lambda : spec.lambdas) {
      for (const auto& est : spec.estimators) {
        for (int s = 0; s < spec.seeds; ++s) {
          SweepRun r;
          r.index = static_cast<int>(grid.size());
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
  std::set<std::string> keys;
  for (const auto& r : grid) {
    if (!keys.insert(r.Key()).second) return Error{"sweep: grid point repeated: " + r.Key()};
  }
  return grid;
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
    const json& m = j.at("metrics");
    RunMetrics& r = s.metrics;
    r.tracking_rmse = m.at("tracking_rmse");
    r.iae = m.at("iae");
    r.overshoot = m.at("overshoot");
    r.max_overshoot = m.at("max_overshoot");
    r.settling_time = m.at("settling_time");
    r.settled_fraction = m.at("settled_fraction");
    r.oscillation = m.at("oscillation");
    r.switching_rate = m.at("switching_rate");
    r.estimator_rmse = m.at("estimator_rmse");
    // NaN (no variance: output only) is stored as null.
    r.mean_nees = m.at("mean_nees").is_null() ? std::nan("") : m.at("mean_nees").get<double>();
    r.estimator_within3 = m.at("estimator_within3");
    r.num_steps = m.at("num_steps");
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
  if (ec) return Error{"sweep: cannot create '" + runs_dir.string() + "': " + ec.message()};

  SweepOutcome outcome;
  outcome.runs.resize(grid.size());
  std::vector<size_t> todo;
  for (size_t i = 0; i < grid.size(); ++i) {
    const fs::path p = runs_dir / (grid[i].Key() + ".json");
    bool reused = false;
    if (fs::exists(p)) {
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

  std::mutex mu;
  std::string first_error;
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
      st = Error{"sweep run " + g.Key() + ": " + s.error()};
    }
    std::lock_guard<std::mutex> lock(mu);
    if (!st.ok()) {
      if (!failed.exchange(true)) first_error = st.error();
      return;
    }
    outcome.runs[todo[t]] = std::move(s).value();
    ++outcome.executed;
    ++done;
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
  if (failed) return Error{first_error};
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

// Text inside a gnuplot single-quoted string: '' is a quote, control characters become spaces
// (a task name must not end the string and inject commands).
std::string GnuplotQuoted(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '\'') {
      out += "''";
    } else if (static_cast<unsigned char>(c) < 0x20) {
      out += ' ';
    } else {
      out += c;
    }
  }
  return out;
}

// True iff `path` is a whole PNG: gnuplot does not check its writes, so on a full disk it exits
// 0 with an empty or cut file; a complete PNG ends with the IEND chunk.
bool IsCompletePng(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  unsigned char head[8] = {}, tail[8] = {};
  bool ok = std::fread(head, 1, 8, f) == 8 && std::fseek(f, -8, SEEK_END) == 0 &&
            std::fread(tail, 1, 8, f) == 8;
  std::fclose(f);
  static const unsigned char kHead[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  static const unsigned char kTail[8] = {'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82};
  return ok && std::memcmp(head, kHead, 8) == 0 && std::memcmp(tail, kTail, 8) == 0;
}

// Runs gnuplot on `script` without a shell (paths may hold any character). Returns its exit
// status, 127 when gnuplot cannot be started.
int RunGnuplot(const std::string& script) {
  pid_t pid = 0;
  std::string prog = "gnuplot";
  std::vector<char*> argv = {prog.data(), const_cast<char*>(script.c_str()), nullptr};
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  const int err = posix_spawnp(&pid, "gnuplot", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (err != 0) return 127;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return 127;
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace

std::vector<CellStats> Aggregate(const std::vector<RunSummary>& runs,
                                 const TrackingCriterion& criterion) {
  std::vector<CellStats> cells;
  std::map<std::tuple<double, double, std::string>, std::vector<const RunSummary*>> groups;
  std::vector<std::tuple<double, double, std::string>> order;
  for (const auto& r : runs) {
    auto key = std::make_tuple(r.dT, r.lambda, r.estimator);
    if (!groups.count(key)) order.push_back(key);
    groups[key].push_back(&r);
  }
  for (const auto& key : order) {
    const auto& g = groups[key];
    CellStats c;
    std::tie(c.dT, c.lambda, c.estimator) = key;
    c.seeds = static_cast<int>(g.size());
    std::vector<double> os, st, sf, rmse, iae, osc, sw, er, nees, w3;
    for (const RunSummary* r : g) {
      os.push_back(r->metrics.overshoot);
      st.push_back(r->metrics.settling_time);
      sf.push_back(r->metrics.settled_fraction);
      rmse.push_back(r->metrics.tracking_rmse);
      iae.push_back(r->metrics.iae);
      osc.push_back(r->metrics.oscillation);
      sw.push_back(r->metrics.switching_rate);
      er.push_back(r->metrics.estimator_rmse);
      if (std::isfinite(r->metrics.mean_nees)) nees.push_back(r->metrics.mean_nees);
      w3.push_back(r->metrics.estimator_within3);
    }
    c.overshoot_mean = Mean(os);
    c.overshoot_sd = Sd(os);
    c.settling_mean = Mean(st);
    c.settled_fraction = Mean(sf);
    c.rmse_mean = Mean(rmse);
    c.iae_mean = Mean(iae);
    c.oscillation_mean = Mean(osc);
    c.switching_mean = Mean(sw);
    c.estimator_rmse_mean = Mean(er);
    c.nees_mean = nees.empty() ? std::nan("") : Mean(nees);
    c.within3_mean = Mean(w3);
    c.margin = std::min(criterion.max_overshoot - c.overshoot_mean,
                        c.settled_fraction - criterion.min_settled);
    c.meets = c.margin >= 0;
    cells.push_back(c);
  }
  return cells;
}

Status WriteSweepReport(const std::vector<CellStats>& cells, const TrackingCriterion& criterion,
                        const std::string& out_dir, const std::string& title) {
  const fs::path dir(out_dir);
  std::string csv =
      "dT,lambda,estimator,seeds,overshoot_mean,overshoot_sd,settling_time_mean,"
      "settled_fraction,tracking_rmse_mean,iae_mean,oscillation_mean,switching_rate_mean,"
      "estimator_rmse_mean,mean_nees_mean,estimator_within3_mean,meets_criterion,margin\n";
  std::string md = fmt::format(
      "# Sweep: {}\n\nCriterion: mean step overshoot <= {:.0f} % and at least {:.0f} % of "
      "steps settled within the 10 % band, over all seeds of a cell. Margin = min(overshoot "
      "limit - overshoot, settled fraction - required fraction).\n\n"
      "| dT (s) | lambda | estimator | seeds | overshoot (%) | settling (s) | settled (%) | "
      "RMSE | oscillation | switching (1/unit/s) | est. RMSE (units) | NEES | within 3 (%) | "
      "meets | margin |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
      title, 100 * criterion.max_overshoot, 100 * criterion.min_settled);
  for (const auto& c : cells) {
    csv += fmt::format(
        "{:g},{:g},{},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},"
        "{:.6g},{:.6g},{:.6g},{},{:.6g}\n",
        c.dT, c.lambda, c.estimator, c.seeds, c.overshoot_mean, c.overshoot_sd, c.settling_mean,
        c.settled_fraction, c.rmse_mean, c.iae_mean, c.oscillation_mean, c.switching_mean,
        c.estimator_rmse_mean, c.nees_mean, c.within3_mean, c.meets ? 1 : 0, c.margin);
    md += fmt::format(
        "| {:g} | {:g} | {} | {} | {:.1f} ± {:.1f} | {:.2f} | {:.0f} | {:.3g} | {:.3f} | {:.4f} "
        "| {:.2f} | {:.2f} | {:.0f} | {} | {:+.3f} |\n",
        c.dT, c.lambda, c.estimator, c.seeds, 100 * c.overshoot_mean, 100 * c.overshoot_sd,
        c.settling_mean, 100 * c.settled_fraction, c.rmse_mean, c.oscillation_mean,
        c.switching_mean, c.estimator_rmse_mean, c.nees_mean, 100 * c.within3_mean,
        c.meets ? "yes" : "no", c.margin);
  }

  // Shortest sampling period meeting the criterion, per estimator and lambda.
  std::string shortest =
      "\n## Shortest sampling period meeting the criterion\n\n"
      "| estimator | lambda | shortest dT (s) | margin | next shorter dT tried "
      "|\n|---|---|---|---|---|\n";
  std::vector<std::pair<std::string, double>> el;
  for (const auto& c : cells) {
    auto key = std::make_pair(c.estimator, c.lambda);
    if (std::find(el.begin(), el.end(), key) == el.end()) el.push_back(key);
  }
  for (const auto& [est, lambda] : el) {
    std::vector<const CellStats*> col;
    for (const auto& c : cells) {
      if (c.estimator == est && c.lambda == lambda) col.push_back(&c);
    }
    std::sort(col.begin(), col.end(), [](auto* a, auto* b) { return a->dT < b->dT; });
    // The shortest dT tried that meets it (a long dT can fail too: too slow to settle).
    int best = -1;
    for (int i = 0; i < static_cast<int>(col.size()) && best < 0; ++i) {
      if (col[i]->meets) best = i;
    }
    if (best < 0) {
      shortest += fmt::format("| {} | {:g} | none of the dT tried | - | - |\n", est, lambda);
    } else {
      const std::string next =
          best > 0 ? fmt::format("{:g} (margin {:+.3f})", col[best - 1]->dT, col[best - 1]->margin)
                   : std::string("none shorter tried");
      shortest += fmt::format("| {} | {:g} | {:g} | {:+.3f} | {} |\n", est, lambda, col[best]->dT,
                              col[best]->margin, next);
    }
  }
  md += shortest;

  Status s = WriteFileAtomically((dir / "table.csv").string(), csv);
  if (!s.ok()) return s;
  s = WriteFileAtomically((dir / "table.md").string(), md);
  if (!s.ok()) return s;

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
        dat += fmt::format("{:g} {:g} {:.4f} {}\n", c.dT, c.lambda, 100 * c.overshoot_mean,
                           c.meets ? 1 : 0);
      }
    }
    dat += "\n\n";
  }
  s = WriteFileAtomically((dir / "stability.dat").string(), dat);
  if (!s.ok()) return s;
  const std::string png = (dir / "stability.png").string();
  const std::string tmp_png = png + ".tmp.png";
  std::string gp = fmt::format(
      "# Stability map of a recruit sweep (made by `recruit sweep`).\n"
      "set terminal png size {},420 font ',10' noenhanced\nset output '{}'\n"
      "set multiplot layout 1,{} title '{}: mean step overshoot (%), ring = meets criterion'\n"
      "set logscale x 2\nset xlabel 'dT (s)'\nset ylabel 'lambda'\n"
      "set cbrange [0:50]\nset palette defined (0 'forest-green', 10 'yellow', 50 'red')\n"
      "set offsets graph 0.1, graph 0.1, graph 0.1, graph 0.1\nunset key\n",
      std::max(480, 460 * static_cast<int>(ests.size())), GnuplotQuoted(tmp_png), ests.size(),
      GnuplotQuoted(title));
  for (size_t i = 0; i < ests.size(); ++i) {
    gp += fmt::format(
        "set title '{0}'\nplot '{1}' index {2} using 1:2:3 with points pt 5 ps 5 palette, "
        "'' index {2} using 1:($4 > 0 ? $2 : 1/0) with points pt 6 ps 6 lc 'black', "
        "'' index {2} using 1:2:(sprintf('%.0f', $3)) with labels offset 0,2.2\n",
        GnuplotQuoted(ests[i]), GnuplotQuoted((dir / "stability.dat").string()), i);
  }
  gp += "unset multiplot\n";
  s = WriteFileAtomically((dir / "stability.gp").string(), gp);
  if (!s.ok()) return s;
  const int slot = RegisterTempFile(tmp_png);  // removed on SIGINT/SIGTERM too
  const int rc = RunGnuplot((dir / "stability.gp").string());
  const bool made = IsCompletePng(tmp_png);
  Status result;
  if (rc == 0 && made) {
    std::error_code ec;
    fs::rename(tmp_png, png, ec);
    if (ec) result = Error{"cannot write '" + png + "': " + ec.message()};
  } else if (rc == 127) {
    std::fprintf(stderr,
                 "sweep: gnuplot is missing; stability.png not made (the data is in "
                 "stability.dat, the script in stability.gp)\n");
  } else {
    result = Error{fmt::format(
        "cannot write '{}': gnuplot exited with status {}{} (disk full?); the data is in "
        "stability.dat, the script in stability.gp",
        png, rc, made ? "" : " and wrote an incomplete image")};
  }
  if (!result.ok() || rc != 0) std::remove(tmp_png.c_str());
  UnregisterTempFile(slot);
  return result;
}

}  // namespace recruit::sim
