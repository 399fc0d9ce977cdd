#include "plot/decimate.h"

#include <algorithm>
#include <cmath>
#include <set>

namespace recruit::plot {

namespace {

int BinOf(double x, double x0, double x1, int buckets) {
  if (!(x1 > x0)) return 0;
  return std::clamp(static_cast<int>((x - x0) / (x1 - x0) * buckets), 0, buckets - 1);
}

}  // namespace

XY DecimateMinMax(const std::vector<double>& x, const std::vector<double>& y, int buckets) {
  const size_t n = std::min(x.size(), y.size());
  if (n < 4 * static_cast<size_t>(std::max(buckets, 1)))
    return {{x.begin(), x.begin() + n}, {y.begin(), y.begin() + n}};
  const double x0 = x.front(), x1 = x.back();
  std::set<size_t> keep;  // ordered indices
  size_t start = 0;
  while (start < n) {
    const int bin = BinOf(x[start], x0, x1, buckets);
    size_t end = start, lo = start, hi = start;
    while (end < n && BinOf(x[end], x0, x1, buckets) == bin) {
      if (!std::isfinite(y[end]))
        keep.insert(end);  // gaps stay gaps
      else if (!std::isfinite(y[lo]) || y[end] < y[lo])
        lo = end;
      if (std::isfinite(y[end]) && (!std::isfinite(y[hi]) || y[end] > y[hi])) hi = end;
      ++end;
    }
    keep.insert({start, lo, hi, end - 1});
    start = end;
  }
  XY out;
  for (size_t i : keep) out.x.push_back(x[i]), out.y.push_back(y[i]);
  return out;
}

XBand DecimateEnvelope(const std::vector<double>& x, const std::vector<double>& lo,
                       const std::vector<double>& hi, int buckets) {
  const size_t n = std::min({x.size(), lo.size(), hi.size()});
  if (n < 4 * static_cast<size_t>(std::max(buckets, 1))) {
    return {{x.begin(), x.begin() + n}, {lo.begin(), lo.begin() + n}, {hi.begin(), hi.begin() + n}};
  }
  const double x0 = x.front(), x1 = x.back();
  XBand out;
  size_t start = 0;
  while (start < n) {
    const int bin = BinOf(x[start], x0, x1, buckets);
    double l = NAN, h = NAN;
    size_t end = start;
    for (; end < n && BinOf(x[end], x0, x1, buckets) == bin; ++end) {
      if (!std::isfinite(lo[end]) || !std::isfinite(hi[end])) continue;
      l = std::isfinite(l) ? std::min(l, lo[end]) : lo[end];
      h = std::isfinite(h) ? std::max(h, hi[end]) : hi[end];
    }
    // A bin holds the envelope from its first to its last x, so a band stays a band.
    out.x.insert(out.x.end(), {x[start], x[end - 1]});
    out.lo.insert(out.lo.end(), {l, l});
    out.hi.insert(out.hi.end(), {h, h});
    start = end;
  }
  return out;
}

}  // namespace recruit::plot
