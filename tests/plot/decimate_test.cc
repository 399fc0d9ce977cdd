// Thinning for drawing keeps what the eye sees: per bucket the extremes of the series (checked
// against a brute-force scan), every gap, the first and last point, and a band's envelope.
#include "plot/decimate.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "common/rng.h"

namespace recruit::plot {
namespace file_decimate_test {

TEST(Decimate, KeepsEachBucketsExtremesAndEnds) {
  Rng rng(5);
  std::normal_distribution<double> noise(0, 1);
  const int n = 100000, buckets = 400;
  std::vector<double> x(n), y(n);
  for (int i = 0; i < n; ++i) x[i] = 0.002 * (i + 1), y[i] = std::sin(x[i]) + 0.1 * noise(rng);
  y[12345] = 50;  // a one-sample spike
  const XY d = DecimateMinMax(x, y, buckets);
  EXPECT_LE(d.x.size(), 4u * buckets);
  EXPECT_EQ(d.x.front(), x.front());
  EXPECT_EQ(d.x.back(), x.back());
  EXPECT_TRUE(std::is_sorted(d.x.begin(), d.x.end()));
  EXPECT_EQ(*std::max_element(d.y.begin(), d.y.end()), 50);
  // Brute force: the min and max of the raw points of every bucket are among the kept points.
  const double x0 = x.front(), x1 = x.back();
  for (int b = 0; b < buckets; ++b) {
    double lo = INFINITY, hi = -INFINITY, klo = INFINITY, khi = -INFINITY;
    for (int i = 0; i < n; ++i) {
      const int bi = std::min(buckets - 1, static_cast<int>((x[i] - x0) / (x1 - x0) * buckets));
      if (bi == b) lo = std::min(lo, y[i]), hi = std::max(hi, y[i]);
    }
    for (size_t k = 0; k < d.x.size(); ++k) {
      const int bk = std::min(buckets - 1, static_cast<int>((d.x[k] - x0) / (x1 - x0) * buckets));
      if (bk == b) klo = std::min(klo, d.y[k]), khi = std::max(khi, d.y[k]);
    }
    ASSERT_EQ(klo, lo) << "bucket " << b;
    ASSERT_EQ(khi, hi) << "bucket " << b;
  }
}

TEST(Decimate, KeepsGapsAndShortSeries) {
  std::vector<double> x(10000), y(10000);
  for (size_t i = 0; i < x.size(); ++i) x[i] = i, y[i] = i % 7;
  y[5000] = NAN;
  const XY d = DecimateMinMax(x, y, 100);
  EXPECT_EQ(std::count_if(d.y.begin(), d.y.end(), [](double v) { return std::isnan(v); }), 1);
  const XY same = DecimateMinMax({0, 1, 2}, {3, 4, 5}, 100);
  EXPECT_EQ(same.y, (std::vector<double>{3, 4, 5}));
}

TEST(Decimate, BandKeepsItsEnvelope) {
  std::vector<double> x(20000), lo(20000), hi(20000);
  for (size_t i = 0; i < x.size(); ++i) x[i] = i, lo[i] = -1 - (i == 777 ? 5 : 0), hi[i] = 1;
  const XBand d = DecimateEnvelope(x, lo, hi, 200);
  EXPECT_LE(d.x.size(), 400u);
  EXPECT_EQ(*std::min_element(d.lo.begin(), d.lo.end()), -6);
  EXPECT_EQ(*std::max_element(d.hi.begin(), d.hi.end()), 1);
  EXPECT_EQ(d.x.front(), 0);
  EXPECT_EQ(d.x.back(), 19999);
}

}  // namespace file_decimate_test
}  // namespace recruit::plot
