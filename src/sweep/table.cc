#include "sweep/table.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

#include "common/atomic_file.h"

namespace recruit::sweep {
namespace fs = std::filesystem;
using sim::CellMetricColumns;
using sim::kMetricCount;
using sim::kMetricFields;
using sim::MetricField;
using sim::MetricIndex;
using sim::MetricValue;
using sim::RunMetrics;
using sim::RunSummary;

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
      const bool past = r->PastDatasheetLimits();
      c.runs_past_limits += past;
      if (margins.back() >= 0 && !past) ++c.seeds_meeting;
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
    c.meets = c.margin >= 0 && c.runs_past_limits == 0;
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
Status WriteTables(const std::vector<CellStats>& cells, const TrackingCriterion& criterion,
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

}  // namespace recruit::sweep
