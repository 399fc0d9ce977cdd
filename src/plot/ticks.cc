#include "plot/ticks.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace recruit::plot {

double NiceStep(double span, int target_intervals) {
  const double raw = span / std::max(1, target_intervals);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / mag;
  // 1e-9: a raw step that is already round (e.g. exactly 2) keeps its mantissa.
  const double nice = f <= 1 + 1e-9 ? 1 : f <= 2 + 1e-9 ? 2 : f <= 5 + 1e-9 ? 5 : 10;
  return nice * mag;
}

std::string FormatTick(double value, double step) {
  const int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  // A value within rounding of zero prints as "0", never "-0" or "-0.0".
  if (std::abs(value) < 1e-6 * step) value = 0;
  std::string s = fmt::format("{:.{}f}", value, decimals);
  if (s.find_first_not_of("-0.") == std::string::npos) s = s.substr(s[0] == '-' ? 1 : 0);
  return s;
}

TickSet MakeTicks(double lo, double hi, int target_intervals) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) lo = 0, hi = 1;
  if (lo > hi) std::swap(lo, hi);
  if (hi - lo <= 1e-12 * std::max(1.0, std::abs(lo))) {
    const double pad = lo == 0 ? 1 : 0.1 * std::abs(lo);
    lo -= pad, hi += pad;
  }
  TickSet t;
  t.step = NiceStep(hi - lo, target_intervals);
  // Integer multiples of the step, so labels are exact and no error accumulates.
  const auto k_lo = static_cast<long long>(std::floor(lo / t.step + 1e-9));
  const auto k_hi = static_cast<long long>(std::ceil(hi / t.step - 1e-9));
  for (long long k = k_lo; k <= k_hi; ++k) {
    t.values.push_back(static_cast<double>(k) * t.step);
    t.labels.push_back(FormatTick(t.values.back(), t.step));
  }
  t.lo = t.values.front();
  t.hi = t.values.back();
  return t;
}

namespace {

void Extend(std::optional<Range>& r, double v) {
  if (!std::isfinite(v)) return;
  if (!r) r = Range{v, v};
  r->lo = std::min(r->lo, v);
  r->hi = std::max(r->hi, v);
}

}  // namespace

std::optional<Range> DataRangeX(const Axes& axes) {
  std::optional<Range> r;
  for (const Series& s : axes.series) {
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (std::isfinite(s.y[i])) Extend(r, s.x[i]);
    }
  }
  for (const Band& b : axes.bands) {
    for (double x : b.x) Extend(r, x);
  }
  return r;
}

std::optional<Range> DataRangeY(const Axes& axes) {
  std::optional<Range> r;
  for (const Series& s : axes.series) {
    for (double y : s.y) Extend(r, y);
  }
  for (const Band& b : axes.bands) {
    for (size_t i = 0; i < b.lo.size() && i < b.hi.size(); ++i) {
      if (std::isfinite(b.lo[i]) && std::isfinite(b.hi[i])) Extend(r, b.lo[i]), Extend(r, b.hi[i]);
    }
  }
  return r;
}

}  // namespace recruit::plot
