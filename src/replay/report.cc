#include "replay/report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace recruit::replay {

Result<ReplayResult> RunReplay(const sim::Task& task, const estimation::BenchLog& log,
                               const ReplayOptions& options) {
  if (options.num_seeds < 3) {
    return Error{"--seeds " + std::to_string(options.num_seeds) + ": at least 3 replays"};
  }
  auto plan = PlanReplay(task, log);
  if (!plan.ok()) return plan.failure();
  ReplayResult r;
  r.log_path = log.path;
  r.task_source = task.source;
  r.task_name = task.name;
  r.dT = log.dT;
  r.time = log.time;
  r.options = options;
  if (r.options.max_lag < 0) r.options.max_lag = 5 * log.dT;
  r.plan = std::move(plan).value();
  const size_t ns = r.plan.signals.size();
  r.runs.assign(ns, {});
  for (int a = 0; a < options.num_seeds; ++a) {
    auto run = ReplayOnce(task, log, r.plan, options.first_seed + a);
    if (!run.ok()) return run.failure();
    for (size_t s = 0; s < ns; ++s) r.runs[s].push_back(std::move((*run)[s]));
  }
  for (size_t s = 0; s < ns; ++s) {
    auto c = CompareSignal(r.plan.signals[s].recorded, r.runs[s], r.dT, r.options.max_lag,
                           options.criterion);
    if (!c.ok()) return c.failure();
    r.flagged = r.flagged || c->flagged;
    r.comparisons.push_back(std::move(c).value());
  }
  return r;
}

namespace {

nlohmann::json ResidualJson(const Residual& x) {
  return {{"rmse", x.rmse}, {"bias", x.bias}, {"lag", x.lag}};
}

// Mean and sample standard deviation of the runs at instant k.
void RunStats(const std::vector<std::vector<double>>& runs, size_t k, double* mean, double* sd,
              double* lo, double* hi) {
  double m = 0;
  *lo = INFINITY, *hi = -INFINITY;
  for (const auto& r : runs) {
    m += r[k] / runs.size();
    *lo = std::min(*lo, r[k]);
    *hi = std::max(*hi, r[k]);
  }
  double ss = 0;
  for (const auto& r : runs) ss += (r[k] - m) * (r[k] - m);
  *mean = m;
  *sd = std::sqrt(ss / (runs.size() - 1));
}

}  // namespace

nlohmann::json ReportJson(const ReplayResult& r) {
  nlohmann::json j;
  j["format"] = "recruit.replay_report";
  j["version"] = 1;
  j["log"] = r.log_path;
  j["task"] = r.task_source;
  j["control_instants"] = r.time.size();
  j["dT"] = r.dT;
  nlohmann::json seeds = nlohmann::json::array();
  for (int a = 0; a < r.options.num_seeds; ++a) seeds.push_back(r.options.first_seed + a);
  j["seeds"] = seeds;
  j["max_lag"] = r.options.max_lag;
  j["criterion"] = {{"ratio_band", r.options.criterion.ratio_band},
                    {"step_ratio_band", r.options.criterion.step_ratio_band},
                    {"z_band", r.options.criterion.z_band}};
  j["flagged"] = r.flagged;
  nlohmann::json signals = nlohmann::json::array();
  for (size_t s = 0; s < r.comparisons.size(); ++s) {
    const SignalComparison& c = r.comparisons[s];
    nlohmann::json same = nlohmann::json::array();
    for (const Residual& x : c.same_plant) same.push_back(ResidualJson(x));
    signals.push_back({{"name", r.plan.signals[s].name},
                       {"unit", r.plan.signals[s].unit},
                       {"recorded", ResidualJson(c.recorded)},
                       {"rmse_ratio", c.rmse_ratio},
                       {"rmse_z", c.rmse_z},
                       {"same_plant_rmse", c.same_plant_rmse},
                       {"same_plant_rmse_sd", c.same_plant_rmse_sd},
                       {"same_plant_bias_sd", c.same_plant_bias_sd},
                       {"same_plant_lag_sd", c.same_plant_lag_sd},
                       {"step_ratio", c.step_ratio},
                       {"step_z", c.step_z},
                       {"same_plant", same},
                       {"flagged", c.flagged}});
  }
  j["signals"] = signals;
  j["ignored_columns"] = r.plan.ignored_angles;
  return j;
}

std::string SignalsCsv(const ReplayResult& r) {
  std::string out = "time";
  for (const Signal& s : r.plan.signals) {
    out += fmt::format(",{0}.recorded,{0}.simulated_mean,{0}.simulated_sd", s.name);
  }
  out += '\n';
  for (size_t k = 0; k < r.time.size(); ++k) {
    out += fmt::format("{}", r.time[k]);
    for (size_t s = 0; s < r.plan.signals.size(); ++s) {
      double mean, sd, lo, hi;
      RunStats(r.runs[s], k, &mean, &sd, &lo, &hi);
      out += fmt::format(",{},{},{}", r.plan.signals[s].recorded[k], mean, sd);
    }
    out += '\n';
  }
  return out;
}

plot::Figure ReplayFigure(const ReplayResult& r) {
  plot::Figure fig;
  const std::string file = r.log_path.substr(r.log_path.find_last_of('/') + 1);
  fig.title =
      fmt::format("replay of {} on {}: {}", file, r.task_name,
                  r.flagged ? "differs from the model (flagged)" : "consistent with the model");
  const plot::Color sim{0.13, 0.4, 0.75, 1}, band{0.13, 0.4, 0.75, 0.25}, rec{0, 0, 0, 1};
  for (size_t s = 0; s < r.plan.signals.size(); ++s) {
    const Signal& sig = r.plan.signals[s];
    const SignalComparison& c = r.comparisons[s];
    const bool angle = sig.unit == "rad";
    const double scale = angle ? 180 / M_PI : 1;
    plot::Axes ax;
    ax.x_label = "time (s)";
    // "flexor force (N)", "angle (deg)", "wrist angle (deg)": the column name is too long.
    const std::string who = sig.name.substr(0, sig.name.find('.'));
    ax.y_label =
        angle ? (who == "angle" ? "angle (deg)" : who + " angle (deg)") : who + " force (N)";
    plot::Band b{fmt::format("simulated, {} seeds (range)", r.options.num_seeds), {}, {}, {}, band};
    plot::Series m{"simulated mean", {}, {}, sim, plot::LineStyle::kSolid, 1.5};
    plot::Series x{fmt::format("recorded: RMSE {0:.3g} {2}, bias {1:.3g} {2}, lag {3:.3g} s{4}",
                               c.recorded.rmse * scale, c.recorded.bias * scale,
                               angle ? "deg" : "N", c.recorded.lag, c.flagged ? " (flagged)" : ""),
                   {},
                   {},
                   rec,
                   plot::LineStyle::kSolid,
                   1};
    for (size_t k = 0; k < r.time.size(); ++k) {
      double mean, sd, lo, hi;
      RunStats(r.runs[s], k, &mean, &sd, &lo, &hi);
      b.x.push_back(r.time[k]);
      b.lo.push_back(lo * scale);
      b.hi.push_back(hi * scale);
      m.x.push_back(r.time[k]);
      m.y.push_back(mean * scale);
      x.x.push_back(r.time[k]);
      x.y.push_back(sig.recorded[k] * scale);
    }
    ax.bands.push_back(std::move(b));
    ax.series.push_back(std::move(m));
    ax.series.push_back(std::move(x));
    fig.panels.push_back(std::move(ax));
  }
  return fig;
}

}  // namespace recruit::replay
