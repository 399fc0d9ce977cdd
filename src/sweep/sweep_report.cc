#include "sweep/sweep_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include "common/atomic_file.h"
#include "sweep/latency.h"
#include "sweep/tune_search.h"

namespace recruit::sweep {
namespace {

namespace fs = std::filesystem;

plot::Color Palette(size_t i) {
  static const plot::Color kColors[] = {{0.12, 0.47, 0.71}, {1.00, 0.50, 0.05}, {0.17, 0.63, 0.17},
                                        {0.84, 0.15, 0.16}, {0.58, 0.40, 0.74}, {0.55, 0.34, 0.29},
                                        {0.89, 0.47, 0.76}, {0.50, 0.50, 0.50}, {0.74, 0.74, 0.13},
                                        {0.09, 0.75, 0.81}};
  return kColors[i % std::size(kColors)];
}

std::string PlantLabel(const std::vector<std::pair<std::string, double>>& v) {
  std::string s;
  for (const auto& [name, x] : v) s += fmt::format("{}{}={:.4g}", s.empty() ? "" : " ", name, x);
  return s.empty() ? "task as given" : s;
}

std::string Base64(const std::string& in) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(in[i]) << 16) |
                       (static_cast<unsigned char>(in[i + 1]) << 8) |
                       static_cast<unsigned char>(in[i + 2]);
    out += {k[v >> 18], k[(v >> 12) & 63], k[(v >> 6) & 63], k[v & 63]};
  }
  if (i + 1 == in.size()) {
    const unsigned v = static_cast<unsigned char>(in[i]) << 16;
    out += {k[v >> 18], k[(v >> 12) & 63], '=', '='};
  } else if (i + 2 == in.size()) {
    const unsigned v =
        (static_cast<unsigned char>(in[i]) << 16) | (static_cast<unsigned char>(in[i + 1]) << 8);
    out += {k[v >> 18], k[(v >> 12) & 63], k[(v >> 6) & 63], '='};
  }
  return out;
}

std::string HtmlEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<') {
      out += "&lt;";
    } else if (c == '>') {
      out += "&gt;";
    } else if (c == '&') {
      out += "&amp;";
    } else {
      out += c;
    }
  }
  return out;
}

// Minimal Markdown to HTML for what ReportMarkdown writes: headings, tables, paragraphs, images.
std::string MarkdownToHtml(const std::string& md, const std::map<std::string, std::string>& pngs,
                           const std::string& title) {
  std::string html = "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>" +
                     HtmlEscape(title) +
                     "</title><style>body{font-family:sans-serif;max-width:70em;margin:2em auto}"
                     "table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:2px 6px;"
                     "text-align:right}img{max-width:100%}</style></head><body>\n";
  bool in_table = false;
  size_t row = 0;
  size_t pos = 0;
  while (pos < md.size()) {
    size_t end = md.find('\n', pos);
    if (end == std::string::npos) end = md.size();
    const std::string line = md.substr(pos, end - pos);
    pos = end + 1;
    if (!line.empty() && line[0] == '|') {
      if (!in_table) {
        html += "<table>\n";
        in_table = true;
        row = 0;
      }
      ++row;
      if (row == 2) continue;  // the |---| rule
      html += "<tr>";
      size_t a = 1;
      while (a < line.size()) {
        size_t b = line.find('|', a);
        if (b == std::string::npos) break;
        std::string cell = line.substr(a, b - a);
        const auto f = cell.find_first_not_of(' '), l = cell.find_last_not_of(' ');
        cell = f == std::string::npos ? "" : cell.substr(f, l - f + 1);
        html += (row == 1 ? "<th>" : "<td>") + HtmlEscape(cell) + (row == 1 ? "</th>" : "</td>");
        a = b + 1;
      }
      html += "</tr>\n";
      continue;
    }
    if (in_table) {
      html += "</table>\n";
      in_table = false;
    }
    if (line.empty()) continue;
    if (line.rfind("## ", 0) == 0) {
      html += "<h2>" + HtmlEscape(line.substr(3)) + "</h2>\n";
    } else if (line.rfind("# ", 0) == 0) {
      html += "<h1>" + HtmlEscape(line.substr(2)) + "</h1>\n";
    } else if (line.rfind("![", 0) == 0) {
      const size_t o = line.find("](");
      const std::string alt = line.substr(2, o - 2);
      const std::string file = line.substr(o + 2, line.size() - o - 3);
      auto it = pngs.find(file);
      if (it != pngs.end()) {
        html += "<p><img alt=\"" + HtmlEscape(alt) + "\" src=\"data:image/png;base64," +
                Base64(it->second) + "\"></p>\n";
      }
    } else {
      html += "<p>" + HtmlEscape(line) + "</p>\n";
    }
  }
  if (in_table) html += "</table>\n";
  return html + "</body></html>\n";
}

// The output-only loop's latency bound on dT for a plant point (NaN: none).
double LatencyBound(const ReportInput& in, int plant, const std::string& estimator, double lambda,
                    double c) {
  if (estimator != "output" || plant >= static_cast<int>(in.latency.size())) return std::nan("");
  return lambda * in.latency[plant] / c;
}

// Margin against dT, one panel per estimator (and lambda), one series per plant point; for output
// only, each plant point's latency bound as a dotted vertical line of its colour.
plot::Figure MarginFigure(const ReportInput& in, double c) {
  plot::Figure fig;
  fig.title = in.title + ": criterion margin against dT (>= 0 meets)";
  std::vector<std::pair<std::string, double>> groups;
  for (const auto& c : in.cells) {
    auto k = std::make_pair(c.estimator, c.lambda);
    if (std::find(groups.begin(), groups.end(), k) == groups.end()) groups.push_back(k);
  }
  for (const auto& [est, lambda] : groups) {
    plot::Axes ax;
    ax.x_label = fmt::format("dT (s), estimator {}, lambda {:g}", est, lambda);
    ax.y_label = "margin";
    std::map<int, plot::Series> by_plant;
    double lo = 1e300, hi = -1e300, ylo = 0, yhi = 0;
    for (const auto& cell : in.cells) {
      if (cell.estimator != est || cell.lambda != lambda) continue;
      plot::Series& s = by_plant[cell.plant];
      s.x.push_back(cell.dT);
      s.y.push_back(cell.margin);
      lo = std::min(lo, cell.dT);
      hi = std::max(hi, cell.dT);
      ylo = std::min(ylo, cell.margin);
      yhi = std::max(yhi, cell.margin);
      if (s.label.empty()) s.label = PlantLabel(cell.plant_values);
    }
    size_t i = 0;
    for (auto& [plant, s] : by_plant) {
      std::vector<size_t> idx(s.x.size());
      for (size_t k = 0; k < idx.size(); ++k) idx[k] = k;
      // C++17 lambdas cannot capture a structured binding by name (clang rejects it).
      const std::vector<double>& x = s.x;
      std::sort(idx.begin(), idx.end(), [&x](size_t a, size_t b) { return x[a] < x[b]; });
      plot::Series sorted = s;
      for (size_t k = 0; k < idx.size(); ++k) {
        sorted.x[k] = s.x[idx[k]];
        sorted.y[k] = s.y[idx[k]];
      }
      sorted.color = Palette(i);
      if (i >= 10) sorted.label.clear();  // a legend of ten is already long
      ax.series.push_back(sorted);
      const double bound = LatencyBound(in, plant, est, lambda, c);
      if (std::isfinite(bound)) {
        plot::Series b;
        b.label = i == 0 ? "latency bound lambda tau / c" : "";
        b.x = {bound, bound};
        b.y = {ylo, yhi};
        b.color = Palette(i);
        b.style = plot::LineStyle::kDotted;
        ax.series.push_back(b);
        lo = std::min(lo, bound);
        hi = std::max(hi, bound);
      }
      ++i;
    }
    plot::Series zero;
    zero.x = {lo, hi};
    zero.y = {0, 0};
    zero.style = plot::LineStyle::kDashed;
    zero.label = "criterion boundary";
    ax.series.push_back(zero);
    fig.panels.push_back(ax);
  }
  return fig;
}

// One panel per plant axis: for each (estimator, lambda) of the recommendations, one series of
// the mean of value(r) over the recommendations at each of the axis's values (the axis's main
// effect, averaged over the other axes' values); value NaN: left out. `shown` maps the mean to
// the plotted y (e.g. exp of a mean of logs: a geometric mean).
template <class Value, class Shown>
std::vector<plot::Axes> MainEffectPanels(const std::vector<Recommendation>& recs,
                                         const std::string& y_label, Value value, Shown shown) {
  std::vector<std::pair<std::string, double>> groups;
  for (const auto& r : recs) {
    auto g = std::make_pair(r.estimator, r.lambda);
    if (std::find(groups.begin(), groups.end(), g) == groups.end()) groups.push_back(g);
  }
  std::vector<plot::Axes> panels;
  const size_t naxes = recs.empty() ? 0 : recs.front().plant_values.size();
  for (size_t k = 0; k < naxes; ++k) {
    plot::Axes ax;
    ax.x_label = recs.front().plant_values[k].first;
    ax.y_label = y_label;
    for (size_t gi = 0; gi < groups.size(); ++gi) {
      std::map<double, std::pair<double, int>> acc;  // axis value -> (sum of values, count)
      for (const auto& r : recs) {
        if (std::make_pair(r.estimator, r.lambda) != groups[gi]) continue;
        const double v = value(r);
        if (std::isnan(v)) continue;
        auto& a = acc[r.plant_values[k].second];
        a.first += v;
        ++a.second;
      }
      plot::Series s;
      s.label = fmt::format("{}, lambda {:g}", groups[gi].first, groups[gi].second);
      s.color = Palette(gi);
      for (const auto& [x, a] : acc) {
        s.x.push_back(x);
        s.y.push_back(shown(a.first / a.second));
      }
      if (!s.x.empty()) ax.series.push_back(s);
    }
    panels.push_back(ax);
  }
  return panels;
}

// Critical dT against each plant axis (main effect: geometric mean over the other axes' values
// at each value of this one), one series per estimator and lambda.
plot::Figure CriticalFigure(const std::string& title, const std::vector<Recommendation>& recs) {
  plot::Figure fig;
  fig.title = title + ": critical dT (margin crosses 0) against each plant axis";
  fig.panels = MainEffectPanels(
      recs, "critical dT (s)",
      [](const Recommendation& r) { return r.found ? std::log(r.critical_dT) : std::nan(""); },
      [](double mean_log) { return std::exp(mean_log); });
  return fig;
}

// The cells a run of which passed a datasheet limit (never recommended), or "".
std::string PastLimitsText(const std::vector<CellStats>& cells) {
  std::string list;
  int n = 0;
  for (const auto& c : cells) {
    if (c.runs_past_limits == 0) continue;
    if (++n <= 12) {
      list += fmt::format("{}plant {} {} lambda {} dT {} ({}/{} runs)", n > 1 ? "; " : "", c.plant,
                          c.estimator, c.lambda, c.dT, c.runs_past_limits, c.seeds);
    }
  }
  if (n == 0) return "";
  return fmt::format(
      "\n{} cell{} had runs past a datasheet limit of their wires and {} never recommended, "
      "whatever their tracking: {}{}.\n",
      n, n > 1 ? "s" : "", n > 1 ? "are" : "is", list, n > 12 ? "; ..." : "");
}

// The tracking the recommended dT achieves against each plant axis: each plant point's mean
// tracking RMSE over the seeds of its cell at the recommended dT, averaged over the other axes'
// values at each value of this one; one series per estimator and lambda. With a failure axis
// (docs/sweep.md) it shows what a failure rate costs in tracking.
plot::Figure TrackingFigure(const ReportInput& in, const std::vector<Recommendation>& recs) {
  plot::Figure fig;
  fig.title = in.title + ": tracking RMSE at the recommended dT against each plant axis";
  auto rmse_at = [&](const Recommendation& r) {
    for (const auto& c : in.cells) {
      if (c.plant == r.plant && c.estimator == r.estimator && c.lambda == r.lambda &&
          c.dT == r.dT) {
        return c.Mean(&sim::RunMetrics::tracking_rmse);
      }
    }
    return std::nan("");
  };
  fig.panels = MainEffectPanels(
      recs, "tracking RMSE at dT" + (in.unit.empty() ? "" : " (" + in.unit + ")"),
      [&](const Recommendation& r) {
        const double e = r.found ? rmse_at(r) : std::nan("");
        return std::isfinite(e) ? e : std::nan("");
      },
      [](double mean) { return mean; });
  return fig;
}

std::string Fmt(double x, const char* spec) {
  return std::isfinite(x) ? fmt::format(fmt::runtime(spec), x) : std::string("-");
}

}  // namespace

std::string ReportMarkdown(const ReportInput& in, const std::vector<Recommendation>& recs,
                           const std::vector<Sensitivity>& sens, bool with_figures,
                           bool with_stability_map) {
  const double c = DelayLoopGainForOvershoot(in.criterion.max_overshoot);
  const bool bound = !in.latency.empty();
  std::string md = fmt::format(
      "# Sampling-period report: {}\n\n{}\n\nCriterion: mean step overshoot <= {:.0f} % and at "
      "least {:.0f} % of steps settled within the band, over all seeds of a cell, and no run of "
      "the cell past a datasheet limit of its wires (temperature, stress). Margin = "
      "min(overshoot limit - overshoot, settled fraction - required fraction). Recommended dT = "
      "the shortest dT tried that meets the criterion (`recruit tune` finds the window and a dT "
      "with room to both edges); se = the standard error of the seeds' own margins; seeds "
      "meeting = the seeds whose own run meets the criterion, with the 95 % Wilson interval of "
      "that fraction; critical dT = where the margin crosses 0, interpolated in log dT "
      "(censored, \"< x\", when the shortest dT tried already meets: extend the grid below "
      "it).{}\n\n"
      "## Recommended dT per plant point\n\n",
      in.title, in.description, 100 * in.criterion.max_overshoot, 100 * in.criterion.min_settled,
      bound ? fmt::format(
                  " Latency bound (output only, docs/sweep.md): dT >= lambda tau / c, tau = the "
                  "bundle's force latency (time to half force after every unit switches on, from "
                  "rest), c = {:.3f} (the delay loop y' = K (r - y(t - tau)) overshoots by {:.0f} "
                  "% at K tau = c).",
                  c, 100 * in.criterion.max_overshoot)
            : std::string());
  const auto& axes =
      recs.empty() ? std::vector<std::pair<std::string, double>>{} : recs.front().plant_values;
  std::string head = "| plant ", rule = "|---";
  for (const auto& [name, v] : axes) {
    head += "| " + name + " ";
    rule += "|---";
  }
  md += head +
        "| estimator | lambda | recommended dT (s) | margin ± se | seeds meeting (95 % interval) | "
        "critical dT (s) |" +
        (bound ? " tau (s) | latency bound dT (s) |" : "") + "\n" + rule +
        "|---|---|---|---|---|---|" + (bound ? "---|---|" : "") + "\n";
  for (const auto& r : recs) {
    std::string row = fmt::format("| {} ", r.plant);
    for (const auto& [name, v] : r.plant_values) row += fmt::format("| {} ", v);
    if (r.found) {
      const Interval w = WilsonInterval(r.seeds_meeting, r.seeds, NormalQuantile(0.95));
      row += fmt::format(
          "| {} | {} | {} | {:+.3f} ± {:.3f} | {}/{} ({:.0f}-{:.0f} %) | {}{} |", r.estimator,
          r.lambda, r.dT, r.margin, r.margin_se, r.seeds_meeting, r.seeds, 100 * w.lo, 100 * w.hi,
          Fmt(r.critical_dT, r.censored ? "< {:.3g}" : "{:.3g}"),
          r.censored ? " (censored: below the shortest dT tried; extend the grid)" : "");
    } else {
      row += fmt::format("| {} | {} | none of the dT tried | - | - | - |", r.estimator, r.lambda);
    }
    if (bound) {
      const double tau =
          r.plant < static_cast<int>(in.latency.size()) ? in.latency[r.plant] : std::nan("");
      row += fmt::format(" {} | {} |", Fmt(tau, "{:.3g}"),
                         Fmt(LatencyBound(in, r.plant, r.estimator, r.lambda, c), "{:.3g}"));
    }
    md += row + "\n";
  }
  md += PastLimitsText(in.cells);
  if (!sens.empty()) {
    md +=
        "\n## Sensitivities: which plant parameter moves the critical dT most\n\n"
        "Least-squares fit of ln(critical dT) on the plant axes (ln x for axes with only positive "
        "values: the slope is then the elasticity d ln dT* / d ln x; otherwise d ln dT* / dx) over "
        "the plant points with an uncensored critical dT. Effect = the factor on dT* across the "
        "swept range of that axis.\n\n"
        "| estimator | lambda | axis | slope | effect over the range | points |\n"
        "|---|---|---|---|---|---|\n";
    for (const auto& s : sens) {
      if (s.fitted) {
        md += fmt::format("| {} | {} | {} | {:+.3f} {} | x{:.3g} | {} |\n", s.estimator, s.lambda,
                          s.axis, s.slope, s.log_axis ? "(d ln dT*/d ln x)" : "(1/unit)", s.effect,
                          s.points);
      } else {
        md += fmt::format("| {} | {} | {} | not fitted | - | {} |\n", s.estimator, s.lambda, s.axis,
                          s.points);
      }
    }
  }
  md += in.seed_reasons;
  if (with_figures) {
    md += "\n## Figures\n\n![criterion margin against dT](margin.png)\n";
    if (!axes.empty()) {
      md += "\n![critical dT against each plant axis](critical_dt.png)\n";
      md += "\n![tracking RMSE at the recommended dT against each plant axis](tracking.png)\n";
    }
    if (with_stability_map) {
      md +=
          "\n![stability map: mean step overshoot per dT and lambda, ring = meets the "
          "criterion](stability.png)\n\n"
          "Stability map: one panel per estimator, a cell per dT tried (across, in increasing "
          "order, equally spaced) and lambda (up), coloured by the cell's mean step overshoot over "
          "its seeds (green 0 %, yellow 10 %, red 50 % or more; the number in the cell, in %), "
          "with a black ring where the cell meets the criterion. In each lambda row the leftmost "
          "ringed cell is the recommended dT; a cell with no ring whose overshoot is within the "
          "limit fails the settling part of the criterion.\n";
    }
    md += "\nSVG versions: margin.svg" +
          std::string(axes.empty() ? "" : ", critical_dt.svg, tracking.svg") +
          ". Full per-cell table: table.md, table.csv.\n";
  }
  return md;
}

Status WriteReport(const ReportInput& in, const std::string& out_dir,
                   const FigureRenderer& render) {
  const fs::path dir(out_dir);
  const auto recs = Recommend(in.cells);
  const auto sens = Sensitivities(recs);
  std::map<std::string, std::string> pngs;
  const double c = DelayLoopGainForOvershoot(in.criterion.max_overshoot);
  std::vector<std::pair<std::string, plot::Figure>> figs = {{"margin", MarginFigure(in, c)}};
  if (!recs.empty() && !recs.front().plant_values.empty()) {
    figs.emplace_back("critical_dt", CriticalFigure(in.title, recs));
    figs.emplace_back("tracking", TrackingFigure(in, recs));
  }
  for (const auto& [name, fig] : figs) {
    const int h = 120 + 260 * static_cast<int>(std::max<size_t>(1, fig.panels.size()));
    for (const auto fmt_ : {plot::Format::kPng, plot::Format::kSvg}) {
      auto bytes = render(fig, 900, h, fmt_);
      if (!bytes.ok()) return Error{"report figure " + name + ": " + bytes.error(), bytes.code()};
      const std::string file = name + (fmt_ == plot::Format::kPng ? ".png" : ".svg");
      if (Status s = WriteFileAtomically((dir / file).string(), *bytes); !s.ok()) return s;
      if (fmt_ == plot::Format::kPng) pngs[file] = *bytes;
    }
  }
  // The dT x lambda map `recruit sweep` draws before the report (sweeps without plant axes).
  bool with_map = false;
  if (in.cells.empty() || in.cells.front().plant_values.empty()) {
    std::error_code ec;
    if (fs::exists(dir / "stability.png", ec)) {
      auto bytes = ReadFile((dir / "stability.png").string());
      if (!bytes.ok()) return Error{"report figure stability: " + bytes.error(), bytes.code()};
      pngs["stability.png"] = std::move(bytes).value();
      with_map = true;
    }
  }
  const std::string md = ReportMarkdown(in, recs, sens, true, with_map);
  if (Status s = WriteFileAtomically((dir / "report.md").string(), md); !s.ok()) return s;
  return WriteFileAtomically((dir / "report.html").string(),
                             MarkdownToHtml(md, pngs, "Sampling-period report: " + in.title));
}

plot::PlotOptions StabilityMapOptions(const std::string& out_dir, const std::string& title,
                                      int num_estimators) {
  plot::PlotOptions o;
  o.stability_map = (fs::path(out_dir) / "stability.dat").string();
  o.out_dir = out_dir;
  o.name = "stability";
  o.formats = "png";
  o.width = std::max(480, 460 * num_estimators);
  o.height = 420;
  o.title = title + ": mean step overshoot (%), ring = meets criterion";
  return o;
}

}  // namespace recruit::sweep
