#include "plot/run_figures.h"

#include <algorithm>
#include <cmath>

namespace recruit::plot {
namespace {

// Colour-blind-safe pairs (Okabe-Ito): per bundle, one hue for the truth, one for the estimate.
const Color kTrue[] = {{0.00, 0.45, 0.70}, {0.00, 0.62, 0.45}};
const Color kEstimate[] = {{0.90, 0.45, 0.00}, {0.80, 0.47, 0.65}};
const Color kReference{0.35, 0.35, 0.35}, kMeasured{0.84, 0.15, 0.16};

const Color& Pick(const Color* palette, size_t i) { return palette[i % 2]; }

Color WithAlpha(Color c, double a) { return c.a = a, c; }

// "flexor: " before a label when the run has more than one bundle.
std::string Prefixed(const RunCsv& csv, size_t b, const std::string& label) {
  return csv.bundles.size() > 1 ? csv.bundles[b] + ": " + label : label;
}

std::vector<double> Scaled(const std::vector<double>& v, double k) {
  std::vector<double> out(v);
  for (double& x : out) x *= k;
  return out;
}

constexpr const char* kTime = "time (s)";

}  // namespace

bool IsAngleRun(const RunCsv& csv, const RunInfo& info) {
  if (!info.unit.empty()) return info.unit == "rad";
  const auto* angle = csv.Find("angle");
  if (!angle) return false;
  const auto& measured = csv.At("measured");
  bool nonzero = false;
  for (size_t i = 0; i < measured.size(); ++i) {
    if (measured[i] != (*angle)[i]) return false;
    nonzero = nonzero || (*angle)[i] != 0;
  }
  return nonzero;
}

Axes TrackingAxes(const RunCsv& csv, bool angle) {
  Axes a;
  a.x_label = kTime;
  a.y_label = angle ? "joint angle (deg)" : "force (N)";
  const double k = angle ? 180.0 / M_PI : 1.0;
  const auto& t = csv.At("time");
  a.series.push_back(
      {"reference", t, Scaled(csv.At("reference"), k), kReference, LineStyle::kDashed, 1.2});
  a.series.push_back({angle ? "angle" : "force", t, Scaled(csv.At("measured"), k), kMeasured,
                      LineStyle::kSolid, 1.2});
  return a;
}

Axes ForceAxes(const RunCsv& csv) {
  Axes a;
  a.x_label = kTime;
  a.y_label = "force (N)";
  const auto& t = csv.At("time");
  const Color refs[] = {kReference, {0.65, 0.65, 0.65}};
  for (size_t b = 0; b < csv.bundles.size(); ++b) {
    const std::string& n = csv.bundles[b];
    a.series.push_back({Prefixed(csv, b, "force reference"), t, csv.At(n + ".force_reference"),
                        refs[b % 2], LineStyle::kDashed, 1.2});
    a.series.push_back({Prefixed(csv, b, "force"), t, csv.At(n + ".force"),
                        b == 0 ? kMeasured : Pick(kTrue, 1), LineStyle::kSolid, 1.2});
  }
  return a;
}

Axes CountAxes(const RunCsv& csv) {
  Axes a;
  a.x_label = kTime;
  a.y_label = "units on";
  const auto& t = csv.At("time");
  for (size_t b = 0; b < csv.bundles.size(); ++b) {
    const std::string& n = csv.bundles[b];
    const auto& est = csv.At(n + ".estimated_on");
    const auto& sd = csv.At(n + ".estimated_on_std");
    Band band{Prefixed(csv, b, "estimate ± 2 sd"), t, est, est,
              WithAlpha(Pick(kEstimate, b), 0.25)};
    bool any = false;
    for (size_t i = 0; i < t.size(); ++i) {
      band.lo[i] = est[i] - 2 * sd[i];
      band.hi[i] = est[i] + 2 * sd[i];
      any = any || (std::isfinite(band.lo[i]) && std::isfinite(band.hi[i]));
    }
    if (any) a.bands.push_back(std::move(band));  // no band without a standard deviation
    a.series.push_back({Prefixed(csv, b, "true"), t, csv.At(n + ".true_on"), Pick(kTrue, b),
                        LineStyle::kSolid, 1.2});
    bool has_estimate = false;
    for (double v : est) has_estimate = has_estimate || std::isfinite(v);
    if (has_estimate) {
      a.series.push_back(
          {Prefixed(csv, b, "estimated"), t, est, Pick(kEstimate, b), LineStyle::kDashed, 1.2});
    }
  }
  return a;
}

Axes BroadcastAxes(const RunCsv& csv) {
  Axes a;
  a.x_label = kTime;
  a.y_label = "probability";
  const auto& t = csv.At("time");
  for (size_t b = 0; b < csv.bundles.size(); ++b) {
    const std::string& n = csv.bundles[b];
    a.series.push_back(
        {Prefixed(csv, b, "p_on"), t, csv.At(n + ".p_on"), Pick(kTrue, b), LineStyle::kSolid, 1});
    a.series.push_back({Prefixed(csv, b, "p_off"), t, csv.At(n + ".p_off"), Pick(kEstimate, b),
                        LineStyle::kDashed, 1});
  }
  // From 0 to the largest broadcast: probabilities are often small (< 0.2), so 0..1 would
  // flatten them.
  double top = 0;
  for (const Series& s : a.series) {
    for (double v : s.y) top = std::isfinite(v) ? std::max(top, v) : top;
  }
  a.y_range = Range{0, top > 0 ? top : 1};
  return a;
}

Axes TemperatureAxes(const RunCsv& csv) {
  Axes a;
  a.x_label = kTime;
  a.y_label = "temperature (°C)";  // mean over the units
  const auto& t = csv.At("time");
  for (size_t b = 0; b < csv.bundles.size(); ++b) {
    a.series.push_back({csv.bundles[b], t, csv.At(csv.bundles[b] + ".mean_temperature"),
                        b == 0 ? kMeasured : Pick(kTrue, 0), LineStyle::kSolid, 1.2});
  }
  return a;
}

std::vector<NamedFigure> MakeRunFigures(const RunCsv& csv, const RunInfo& info) {
  const std::string title = TitleOf(info);
  const bool angle = IsAngleRun(csv, info);
  std::vector<NamedFigure> out = {{"tracking", {title, {TrackingAxes(csv, angle)}}}};
  // An angle task's bundles track force references of their own (from the outer loop).
  if (angle) out.push_back({"forces", {title, {ForceAxes(csv)}}});
  out.push_back({"count", {title, {CountAxes(csv)}}});
  out.push_back({"broadcast", {title, {BroadcastAxes(csv)}}});
  out.push_back({"temperature", {title, {TemperatureAxes(csv)}}});
  Figure all{title, {}};
  for (const auto& f : out) all.panels.push_back(f.figure.panels[0]);
  out.push_back({"all", std::move(all)});
  return out;
}

}  // namespace recruit::plot
