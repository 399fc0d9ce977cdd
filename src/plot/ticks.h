// Axis ticks: round values in 1-2-5 x 10^k steps that cover the data range. Pure functions.
#pragma once

#include <string>
#include <vector>

#include "plot/figure.h"

namespace recruit::plot {

struct TickSet {
  double step = 1;             // 1, 2 or 5 x 10^k
  double lo = 0, hi = 1;       // the axis range: the first and last tick
  std::vector<double> values;  // lo, lo + step, ..., hi (each an integer multiple of step)
  std::vector<std::string> labels;
};

// The 1-2-5 x 10^k step nearest above span / target_intervals (span > 0, target >= 1).
double NiceStep(double span, int target_intervals);

// Ticks covering [lo, hi] with about `target_intervals` intervals. A degenerate range (lo == hi)
// is widened around its value; non-finite bounds give the range 0..1.
TickSet MakeTicks(double lo, double hi, int target_intervals);

// The label of a tick: as many decimals as the step needs, never "-0".
std::string FormatTick(double value, double step);

// The finite min and max of the x (or y) values of an axes' series and bands; nullopt if none.
std::optional<Range> DataRangeX(const Axes& axes);
std::optional<Range> DataRangeY(const Axes& axes);

}  // namespace recruit::plot
