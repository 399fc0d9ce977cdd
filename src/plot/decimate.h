// Thinning of long series for drawing: a run's CSV has up to one row per physics step (1e5 rows
// for 200 s at 2 ms), far more than the pixels of a plot. Keeping each bucket's first, minimum,
// maximum and last point keeps every spike visible. Pure functions.
#pragma once

#include <vector>

namespace recruit::plot {

struct XY {
  std::vector<double> x, y;
};

// Splits [x0, x1] into `buckets` equal bins and keeps, per bin, its first, min, max and last
// finite point in x order. A non-finite y is kept (it marks a gap). Series shorter than
// 4 x buckets are returned unchanged.
XY DecimateMinMax(const std::vector<double>& x, const std::vector<double>& y, int buckets);

struct XBand {
  std::vector<double> x, lo, hi;
};

// Per bin: the bin's first x, the minimum lo and the maximum hi (the band's envelope).
XBand DecimateEnvelope(const std::vector<double>& x, const std::vector<double>& lo,
                       const std::vector<double>& hi, int buckets);

}  // namespace recruit::plot
