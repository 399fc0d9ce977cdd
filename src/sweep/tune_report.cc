// tune.md and tune.json: the window per plant point, estimator and lambda with its censored
// edges said as such, the recommended dT with its margin to both edges, and per dT tried why it
// fails, the Wilson interval on the fraction of seeds meeting, the overshoot's mean, 95th
// percentile and worst step, the datasheet limits and the estimator's quality.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <tuple>

#include "common/atomic_file.h"
#include "sweep/tune.h"

namespace recruit::sweep {
namespace {

namespace fs = std::filesystem;

std::string TunePlantLabel(const std::vector<std::pair<std::string, double>>& v) {
  std::string s;
  for (const auto& [name, x] : v) s += fmt::format("{}{}={:.4g}", s.empty() ? "" : " ", name, x);
  return s.empty() ? "task as given" : s;
}

std::string Why(const DtRow& r) {
  std::string s;
  auto part = [&](int n, const char* what) {
    if (n > 0) s += fmt::format("{}{} {}/{}", s.empty() ? "" : ", ", what, n, r.seeds);
  };
  part(r.fail_overshoot, "overshoot");
  part(r.fail_settling, "settling");
  part(r.fail_worst_step, "worst step");
  part(r.fail_limits, "limits");
  return s.empty() ? "-" : s;
}

const DtRow* RowAt(const TuneColumn& c, double dT) {
  for (const auto& r : c.rows) {
    if (r.dT == dT) return &r;
  }
  return nullptr;
}

std::string FractionText(const DtRow& r) {
  return fmt::format("{}/{} ({:.0f}-{:.0f} %)", r.meeting, r.seeds, 100 * r.fraction.lo,
                     100 * r.fraction.hi);
}

// No period meets: the closest one (the largest fraction meeting; among equals, the fewest breaches
// of the criterion's parts per seed), its verdict and why, and what would decide a marginal one.
std::string NoWindowText(const TuneColumn& c, const TuneSettings& s) {
  auto score = [](const DtRow& r) {
    const double n = std::max(1, r.seeds);
    const int parts = r.fail_overshoot + r.fail_settling + r.fail_worst_step + r.fail_limits;
    return std::make_pair(r.meeting / n, -parts / n);
  };
  const DtRow* best = nullptr;
  for (const auto& r : c.rows) {
    if (!best || score(r) > score(*best)) best = &r;
  }
  if (!best) return "none: no dT tried meets";
  int runs = 0, past_limits = 0;
  for (const auto& r : c.rows) {
    runs += r.seeds;
    past_limits += r.fail_limits;
  }
  if (past_limits == runs) {
    return "none: every run is past a datasheet limit (below: Datasheet limits); change the design";
  }
  std::string text = fmt::format("none: no dT tried meets; closest {} s, {}, {}", best->dT,
                                 FractionText(*best), VerdictName(best->verdict));
  if (best->verdict == Verdict::kMarginal) {
    text +=
        fmt::format(" (undecided at {} seeds: raise --max-seeds or lower --level)", s.max_seeds);
  }
  return text + (best->meeting < best->seeds ? ": " + Why(*best) : std::string());
}

std::string Percent(double x) { return std::isfinite(x) ? fmt::format("{:.1f}", 100 * x) : "-"; }

// Each recommended dT on the seeds the search never used (TuneDefinition::check_seeds).
std::string NewSeedsMarkdown(const TuneDefinition& d, const TuneOutcome& o) {
  std::string md;
  for (const auto& c : o.columns) {
    if (c.check.seeds == 0) continue;
    const DtRow& r = c.check;
    md += fmt::format("| {} | {} | {} | {} | {} | {} | {} / {} / {} | {:.3f}: {} |\n",
                      TunePlantLabel(c.plant_values), c.estimator, c.lambda, r.dT, FractionText(r),
                      Why(r), Percent(r.overshoot_mean), Percent(r.overshoot_p95),
                      Percent(r.overshoot_worst), c.check_p,
                      c.check_p < 0.05 ? "**refuted**" : "holds");
  }
  if (md.empty()) return md;
  return fmt::format(
             "\n## The recommendation on new seeds\n\nEach recommended dT run on {} seeds the "
             "search never used (base seed {}, under check/). The claim \"at least {:.2f} of "
             "seeds meet\" is refuted at 5 % when P(X <= seeds meeting) < 0.05 for X ~ "
             "Binomial(seeds, {:.2f}).\n\n| plant | estimator | lambda | dT (s) | seeds meeting "
             "(95 % interval) | why it fails (seeds) | overshoot mean / p95 / worst step (%) | "
             "P(X <= meeting): claim |\n|---|---|---|---|---|---|---|---|\n",
             d.check_seeds, d.check_base_seed, d.settings.level, d.settings.level) +
         md;
}

std::string EdgeText(const TuneColumn& c, const TuneSettings& s, bool lower,
                     const DtLattice& lattice) {
  if (!c.window.found) return "-";
  const Edge& e = lower ? c.window.lower : c.window.upper;
  if (e.censored) {
    const double first = lattice.dT(0), last = lattice.dT(lattice.size() - 1);
    if (lower) {
      return fmt::format(
          "< {} (censored: below the shortest dT tried; extend the range, e.g. --dT-range "
          "{:g},{:g})",
          first, std::max(s.dT_min / 4, s.dT_quantum), s.dT_max);
    }
    return fmt::format(
        "> {} (censored: above the longest dT tried; extend the range, e.g. --dT-range {:g},{:g})",
        last, s.dT_min, s.dT_max * 4);
  }
  // The period beyond the edge fails, or is marginal (undecided at max_seeds: the edge is then
  // where the claim stops being made, not where the fraction is known to fall below the level).
  const DtRow* beyond = RowAt(c, lattice.dT(e.fails));
  return fmt::format("{:.3g} ({} at {}, meets at {})", lower ? c.lower_edge : c.upper_edge,
                     beyond ? VerdictName(beyond->verdict) : "fails", lattice.dT(e.fails),
                     lattice.dT(e.meets));
}

plot::Series VerticalLine(double x, const std::string& label, plot::Color color,
                          plot::LineStyle style, double width = 1.5) {
  plot::Series v;
  v.label = label;
  v.x = {x, x};
  v.y = {0, 1};
  v.color = color;
  v.style = style;
  v.width = width;
  return v;
}

// One panel per search: the fraction of seeds meeting against log10 dT with its Wilson band, the
// level, the edges (solid; a censored edge dotted at the lattice's end with an arrowhead pointing
// out of the range) and the recommended dT.
plot::Figure WindowFigure(const PreparedSweep& p, const TuneDefinition& d, const TuneOutcome& o) {
  const DtLattice lattice(d.settings);
  plot::Figure fig;
  fig.title = p.task.name + ": fraction of seeds meeting the criterion against dT";
  const plot::Color blue{0.12, 0.47, 0.71}, red{0.84, 0.15, 0.16}, green{0.17, 0.63, 0.17},
      grey{0.4, 0.4, 0.4};
  for (const auto& c : o.columns) {
    plot::Axes ax;
    ax.x_label = fmt::format("log10 dT (s); {}, {}, lambda {:g}", TunePlantLabel(c.plant_values),
                             c.estimator, c.lambda);
    ax.y_label = "fraction meeting";
    ax.y_range = plot::Range{0, 1};
    plot::Band band;
    band.label = fmt::format("{:.0f} % Wilson interval", 100 * d.settings.confidence);
    band.color = {blue.r, blue.g, blue.b, 0.25};
    plot::Series frac;
    frac.label = "seeds meeting / seeds";
    frac.color = blue;
    for (const auto& r : c.rows) {
      const double x = std::log10(r.dT);
      band.x.push_back(x);
      band.lo.push_back(r.fraction.lo);
      band.hi.push_back(r.fraction.hi);
      frac.x.push_back(x);
      frac.y.push_back(r.seeds ? static_cast<double>(r.meeting) / r.seeds : std::nan(""));
    }
    ax.bands.push_back(band);
    ax.series.push_back(frac);
    const double x0 = std::log10(lattice.dT(0)), x1 = std::log10(lattice.dT(lattice.size() - 1));
    plot::Series level;
    level.label = fmt::format("level {:.2f}", d.settings.level);
    level.x = {x0, x1};
    level.y = {d.settings.level, d.settings.level};
    level.color = grey;
    level.style = plot::LineStyle::kDashed;
    ax.series.push_back(level);
    if (c.window.found) {
      for (const bool lower : {true, false}) {
        const Edge& e = lower ? c.window.lower : c.window.upper;
        const double x = std::log10(lower ? c.lower_edge : c.upper_edge);
        const std::string name = lower ? "lower edge" : "upper edge";
        if (!e.censored) {
          ax.series.push_back(VerticalLine(x, name, red, plot::LineStyle::kSolid));
          continue;
        }
        ax.series.push_back(
            VerticalLine(x, name + " (censored: beyond the range)", red, plot::LineStyle::kDotted));
        // An arrowhead at mid height pointing out of the range.
        const double w = 0.04 * (x1 - x0), dir = lower ? -1 : 1;
        plot::Series arrow;
        arrow.x = {x, x + dir * w, x};
        arrow.y = {0.45, 0.5, 0.55};
        arrow.color = red;
        arrow.width = 1.5;
        ax.series.push_back(arrow);
      }
      ax.series.push_back(VerticalLine(std::log10(c.recommended), "recommended dT", green,
                                       plot::LineStyle::kDashed));
    }
    fig.panels.push_back(ax);
  }
  return fig;
}

}  // namespace

std::string SeedReasonsMarkdown(const std::vector<SweepRun>& grid,
                                const std::vector<sim::RunSummary>& runs,
                                const TrackingCriterion& criterion) {
  using Key = std::tuple<int, std::string, double, double>;
  std::vector<Key> order;
  std::map<Key, std::vector<sim::RunSummary>> cells;
  std::map<Key, const SweepRun*> first;
  for (size_t i = 0; i < runs.size() && i < grid.size(); ++i) {
    const Key k{grid[i].plant, grid[i].estimator, grid[i].lambda, grid[i].dT};
    if (!cells.count(k)) {
      order.push_back(k);
      first[k] = &grid[i];
    }
    cells[k].push_back(runs[i]);
  }
  TuneCriterion c;
  c.tracking = criterion;
  const TuneSettings s;  // the 95 % interval
  std::string md =
      "\n## Seeds one by one\n\nEach seed's own run against the criterion (its mean step "
      "overshoot, its settled fraction, its wires' datasheet limits): the seeds meeting with the "
      "95 % Wilson interval of that fraction, why the others fail (each part, on how many "
      "seeds), and the step overshoot over every step of every seed.\n\n"
      "| plant | estimator | lambda | dT (s) | seeds meeting (95 % interval) | why it fails "
      "(seeds) "
      "| overshoot mean / p95 / worst step (%) | runs past a limit |\n"
      "|---|---|---|---|---|---|---|---|\n";
  for (const Key& k : order) {
    const DtRow r = SummarizeDt(std::get<3>(k), cells[k], c, s);
    md += fmt::format("| {} | {} | {} | {} | {}/{} ({:.0f}-{:.0f} %) | {} | {} / {} / {} | {} |\n",
                      TunePlantLabel(first[k]->plant_values), std::get<1>(k), std::get<2>(k),
                      std::get<3>(k), r.meeting, r.seeds, 100 * r.fraction.lo, 100 * r.fraction.hi,
                      Why(r), Percent(r.overshoot_mean), Percent(r.overshoot_p95),
                      Percent(r.overshoot_worst), r.fail_limits);
  }
  return md;
}

std::string TuneMarkdown(const PreparedSweep& p, const TuneDefinition& d, const TuneOutcome& o) {
  const TuneSettings& s = d.settings;
  const DtLattice lattice(s);
  const TuneCriterion& c = d.criterion;
  std::string md = fmt::format("# Tune: {}\n\n", p.task.name);
  md += fmt::format(
      "Searched: dT in [{}, {}] s on a log lattice of {} periods (neighbours a factor {:.3f} "
      "apart, tolerance {:.0f} %), per plant point ({}), estimator ({}) and lambda ({}), runs of "
      "{:g} s.\n\n",
      s.dT_min, s.dT_max, lattice.size(), lattice.ratio(), 100 * s.tolerance, p.plant.size(),
      fmt::join(p.spec.estimators, ", "), fmt::join(p.spec.lambdas, ", "),
      p.spec.duration ? *p.spec.duration : p.task.duration);
  md += fmt::format(
      "Criterion, per run (seed): mean step overshoot <= {:.0f} %, at least {:.0f} % of steps "
      "settled within the 10 % band{}, and no wire above its datasheet limits (temperature, "
      "stress). A dT *meets* when the {:.0f} % Wilson interval of the fraction of seeds meeting "
      "lies at or above {:.2f}, *fails* when it lies below; *open* cells get more seeds (doubling "
      "from {} up to {}); a cell still straddling {:.2f} at {} seeds is *marginal* and left out of "
      "the window.\n\n",
      100 * c.tracking.max_overshoot, 100 * c.tracking.min_settled,
      std::isfinite(c.max_step_overshoot)
          ? fmt::format(", worst step overshoot <= {:.0f} %", 100 * c.max_step_overshoot)
          : std::string(),
      100 * s.confidence, s.level, s.initial_seeds, s.max_seeds, s.level, s.max_seeds);
  md += fmt::format(
      "Runs: {} ({} made, {} reused) in {} rounds. The lattice grid that gives the same answer "
      "(every period of the lattice with the most seeds any period needed, per search): {} runs, "
      "{:.1f}x more.\n\n",
      o.runs, o.executed, o.reused, o.rounds, o.grid_runs,
      o.runs ? static_cast<double>(o.grid_runs) / o.runs : 0.0);

  md +=
      "## Windows\n\n| plant | estimator | lambda | lower edge (s) | upper edge (s) | recommended "
      "dT (s) | margin to the edges | seeds meeting there (95 % interval) |\n"
      "|---|---|---|---|---|---|---|---|\n";
  for (const auto& col : o.columns) {
    std::string rec = NoWindowText(col, s), margin = "-", frac = "-";
    if (col.window.found) {
      rec = fmt::format("{}", col.recommended);
      margin = fmt::format(
          "x{:.2f} above the lower{}, x{:.2f} below the upper{}", col.recommended / col.lower_edge,
          col.window.lower.censored ? " (at least)" : "", col.upper_edge / col.recommended,
          col.window.upper.censored ? " (at least)" : "");
      if (const DtRow* r = RowAt(col, col.recommended)) frac = FractionText(*r);
    }
    md +=
        fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} |\n", TunePlantLabel(col.plant_values),
                    col.estimator, col.lambda, EdgeText(col, s, true, lattice),
                    EdgeText(col, s, false, lattice), rec, margin, frac);
  }
  // Meeting periods outside the window (beyond a marginal or failing one): said, not hidden.
  for (const auto& col : o.columns) {
    if (!col.window.found) continue;
    std::vector<std::string> also;
    for (const auto& r : col.rows) {
      if (r.verdict == Verdict::kMeets && (r.dT < lattice.dT(col.window.lower.meets) ||
                                           r.dT > lattice.dT(col.window.upper.meets))) {
        also.push_back(fmt::format("{} s ({})", r.dT, FractionText(r)));
      }
    }
    if (!also.empty()) {
      md += fmt::format(
          "\n{} / {} / lambda {}: also meeting outside the window, beyond a period that does not "
          "(see its row below): {}. The window is the longest run of meeting periods tried.\n",
          TunePlantLabel(col.plant_values), col.estimator, col.lambda, fmt::join(also, ", "));
    }
  }
  md += fmt::format(
      "\nThe recommended dT is the meeting dT tried farthest (in log dT) from both edges, not the "
      "shortest. **The upper edge depends on the hold time**: past it steps stop settling within "
      "their hold; the task's shortest step hold is {:g} s, so a longer hold moves the upper edge "
      "up and a shorter one down (the lower edge, set by overshoot, does not depend on it). "
      "\"why it fails\" below says which part of the criterion each dT breaks, on how many "
      "seeds.\n",
      o.shortest_hold);

  md += NewSeedsMarkdown(d, o);
  for (const auto& col : o.columns) {
    md += fmt::format("\n## {} / {} / lambda {}\n\n", TunePlantLabel(col.plant_values),
                      col.estimator, col.lambda);
    md +=
        "| dT (s) | seeds | meeting | fraction meeting (95 % interval) | verdict | why it fails "
        "(seeds) | overshoot mean / p95 / worst step (%) | settled (%) | peak / limit: "
        "temperature, stress | est. RMSE (units) | NEES |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& r : col.rows) {
      md += fmt::format(
          "| {} | {} | {} | {:.0f}-{:.0f} % | {} | {} | {} / {} / {} | {:.0f} | {:.2f}{}, {:.2f}{} "
          "| {:.2f} | {} |\n",
          r.dT, r.seeds, r.meeting, 100 * r.fraction.lo, 100 * r.fraction.hi,
          VerdictName(r.verdict), Why(r), Percent(r.overshoot_mean), Percent(r.overshoot_p95),
          Percent(r.overshoot_worst), 100 * r.settled_mean, r.worst_temperature_ratio,
          r.worst_temperature_ratio > 1 ? " (exceeded)" : "", r.worst_stress_ratio,
          r.worst_stress_ratio > 1 ? " (exceeded)" : "", r.estimator_rmse,
          std::isfinite(r.mean_nees) ? fmt::format("{:.2f}", r.mean_nees) : std::string("-"));
    }
    for (const auto& r : col.rows) {
      for (const auto& [text, n] : r.warnings) {
        md += fmt::format("\nAt dT {} s, {} of {} runs: {}\n", r.dT, n, r.seeds, text);
      }
    }
    int limit_runs = 0;
    double worst_t = 0, worst_s = 0;
    for (const auto& r : col.rows) {
      limit_runs += r.fail_limits;
      worst_t = std::max(worst_t, r.worst_temperature_ratio);
      worst_s = std::max(worst_s, r.worst_stress_ratio);
    }
    md += fmt::format(
        "\nDatasheet limits: {} of {} runs exceeded one (worst peak / limit: temperature {:.2f}, "
        "stress {:.2f}); such runs do not meet, so the window holds only dT within limits.\n",
        limit_runs, col.runs, worst_t, worst_s);
  }
  return md;
}

nlohmann::json TuneJson(const TuneDefinition& d, const TuneOutcome& o) {
  const TuneSettings& s = d.settings;
  auto num = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(); };
  nlohmann::json j;
  j["settings"] = {{"dT_min", s.dT_min},
                   {"dT_max", s.dT_max},
                   {"tolerance", s.tolerance},
                   {"level", s.level},
                   {"confidence", s.confidence},
                   {"initial_points", s.initial_points},
                   {"initial_seeds", s.initial_seeds},
                   {"max_seeds", s.max_seeds}};
  j["criterion"] = {{"max_overshoot", d.criterion.tracking.max_overshoot},
                    {"min_settled", d.criterion.tracking.min_settled},
                    {"max_step_overshoot", num(d.criterion.max_step_overshoot)}};
  j["runs"] = o.runs;
  j["executed"] = o.executed;
  j["reused"] = o.reused;
  j["rounds"] = o.rounds;
  j["grid_runs"] = o.grid_runs;
  j["shortest_hold"] = num(o.shortest_hold);
  const DtLattice lattice(s);
  nlohmann::json cols = nlohmann::json::array();
  for (const auto& c : o.columns) {
    nlohmann::json pv = nlohmann::json::object();
    for (const auto& [name, v] : c.plant_values) pv[name] = v;
    auto edge = [&](const Edge& e, double est) {
      return nlohmann::json{{"dT", num(est)},
                            {"censored", e.censored},
                            {"meets", e.meets >= 0 ? num(lattice.dT(e.meets)) : nlohmann::json()},
                            {"fails", e.fails >= 0 ? num(lattice.dT(e.fails)) : nlohmann::json()},
                            {"resolved", e.resolved}};
    };
    nlohmann::json rows = nlohmann::json::array();
    for (const auto& r : c.rows) {
      rows.push_back({{"dT", r.dT},
                      {"seeds", r.seeds},
                      {"meeting", r.meeting},
                      {"fraction_lo", r.fraction.lo},
                      {"fraction_hi", r.fraction.hi},
                      {"verdict", VerdictName(r.verdict)},
                      {"fail_overshoot", r.fail_overshoot},
                      {"fail_settling", r.fail_settling},
                      {"fail_worst_step", r.fail_worst_step},
                      {"fail_limits", r.fail_limits},
                      {"overshoot_mean", num(r.overshoot_mean)},
                      {"overshoot_p95", num(r.overshoot_p95)},
                      {"overshoot_worst", num(r.overshoot_worst)},
                      {"settled_mean", r.settled_mean},
                      {"worst_temperature_ratio", r.worst_temperature_ratio},
                      {"worst_stress_ratio", r.worst_stress_ratio},
                      {"estimator_rmse", r.estimator_rmse},
                      {"mean_nees", num(r.mean_nees)},
                      {"warnings", r.warnings}});
    }
    cols.push_back({{"plant", c.plant},
                    {"plant_values", pv},
                    {"estimator", c.estimator},
                    {"lambda", c.lambda},
                    {"window_found", c.window.found},
                    {"lower_edge", edge(c.window.lower, c.lower_edge)},
                    {"upper_edge", edge(c.window.upper, c.upper_edge)},
                    {"recommended_dT", num(c.recommended)},
                    {"check", c.check.seeds == 0
                                  ? nlohmann::json()
                                  : nlohmann::json{{"seeds", c.check.seeds},
                                                   {"meeting", c.check.meeting},
                                                   {"fraction_lo", c.check.fraction.lo},
                                                   {"fraction_hi", c.check.fraction.hi},
                                                   {"fail_overshoot", c.check.fail_overshoot},
                                                   {"fail_settling", c.check.fail_settling},
                                                   {"fail_limits", c.check.fail_limits},
                                                   {"binomial_p", c.check.seeds ? c.check_p : 0},
                                                   {"refuted", c.check_p < 0.05}}},
                    {"runs", c.runs},
                    {"dTs", rows}});
  }
  j["columns"] = cols;
  return j;
}

Status WriteTuneReport(const PreparedSweep& p, const TuneDefinition& d, const TuneOutcome& o,
                       const FigureRenderer& render) {
  const fs::path dir(d.sweep.out);
  if (render) {
    const plot::Figure fig = WindowFigure(p, d, o);
    const int h = 120 + 260 * static_cast<int>(std::max<size_t>(1, fig.panels.size()));
    for (const auto f : {plot::Format::kPng, plot::Format::kSvg}) {
      auto bytes = render(fig, 900, h, f);
      if (!bytes.ok()) return Error{"tune figure: " + bytes.error(), bytes.code()};
      const std::string file = f == plot::Format::kPng ? "window.png" : "window.svg";
      RECRUIT_TRY(WriteFileAtomically((dir / file).string(), *bytes));
    }
  }
  RECRUIT_TRY(WriteFileAtomically((dir / "tune.json").string(), TuneJson(d, o).dump(1) + "\n"));
  std::string md = TuneMarkdown(p, d, o);
  if (render) {
    md +=
        "\n## Figure\n\n![fraction of seeds meeting against dT, with the window's edges (dotted "
        "with an arrowhead: censored) and the recommended dT](window.png)\n";
  }
  return WriteFileAtomically((dir / "tune.md").string(), md);
}

}  // namespace recruit::sweep
