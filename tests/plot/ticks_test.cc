// Tick rules: round values (1, 2 or 5 x 10^k apart, each a multiple of the step) covering the
// data range, labels that read back as the values, never "-0". Checked on many random ranges.
#include "plot/ticks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>
#include <regex>

#include "common/rng.h"

namespace recruit::plot {
namespace file_ticks_test {

// The mantissa of a 1-2-5 step, recomputed from its decimal digits (not from NiceStep's code).
bool IsOneTwoFive(double step) {
  const double m = step / std::pow(10.0, std::floor(std::log10(step) + 1e-12));
  for (double ok : {1.0, 2.0, 5.0, 10.0}) {
    if (std::abs(m - ok) < 1e-9 * ok) return true;
  }
  return false;
}

bool IsNegativeZero(const std::string& label) {
  return std::regex_match(label, std::regex("-0(\\.0*)?"));
}

TEST(Ticks, RandomRangesGetRoundTicksThatCoverThem) {
  Rng rng(20261123);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 5000; ++trial) {
    const double span = std::pow(10.0, -4 + 10 * u(rng));  // 1e-4 .. 1e6
    const double offset = (u(rng) - 0.5) * 6 * span;
    const double lo = u(rng) < 0.5 ? offset : 0;  // half the ranges start at 0
    const double hi = lo + span;
    const int target = 2 + static_cast<int>(9 * u(rng));
    const TickSet t = MakeTicks(lo, hi, target);
    SCOPED_TRACE(::testing::Message() << "range [" << lo << ", " << hi << "] target " << target);
    ASSERT_TRUE(IsOneTwoFive(t.step)) << t.step;
    ASSERT_GE(t.values.size(), 2u);
    EXPECT_LE(t.values.front(), lo);
    EXPECT_GE(t.values.back(), hi);
    EXPECT_GT(t.values.front(), lo - t.step);  // no more than one step beyond the data
    EXPECT_LT(t.values.back(), hi + t.step);
    const double intervals = static_cast<double>(t.values.size() - 1);
    // The step is the 1-2-5 value at or above span / target, at most 2.5x above it.
    EXPECT_LE(intervals, target + 2);
    EXPECT_GE(intervals, target / 2.5 - 1e-9);
    for (size_t i = 0; i < t.values.size(); ++i) {
      const double k = t.values[i] / t.step;
      ASSERT_NEAR(k, std::round(k), 1e-6) << t.values[i];
      const double read = std::strtod(t.labels[i].c_str(), nullptr);
      ASSERT_NEAR(read, t.values[i], 1e-6 * t.step) << "label " << t.labels[i];
      ASSERT_FALSE(IsNegativeZero(t.labels[i])) << t.labels[i];
      if (i > 0) {
        ASSERT_NE(t.labels[i], t.labels[i - 1]);
      }
    }
  }
}

TEST(Ticks, ZeroIsNeverNegative) {
  EXPECT_EQ(FormatTick(-0.0, 1), "0");
  EXPECT_EQ(FormatTick(-1e-17, 0.1), "0.0");
  EXPECT_EQ(FormatTick(-0.04, 1), "0");  // rounds to zero at the step's precision
  for (const auto& [lo, hi] : {std::pair{-0.3, 0.3}, {-1e-17, 1.0}, {-2.0, -1e-15}, {-0.7, 0.0}}) {
    for (int target = 1; target <= 10; ++target) {
      for (const auto& l : MakeTicks(lo, hi, target).labels) EXPECT_FALSE(IsNegativeZero(l)) << l;
    }
  }
}

TEST(Ticks, LabelsUseTheStepsDecimals) {
  const TickSet t = MakeTicks(0, 1, 5);
  EXPECT_DOUBLE_EQ(t.step, 0.2);
  EXPECT_EQ(t.labels, (std::vector<std::string>{"0.0", "0.2", "0.4", "0.6", "0.8", "1.0"}));
  const TickSet big = MakeTicks(0, 200, 4);
  EXPECT_EQ(big.labels, (std::vector<std::string>{"0", "50", "100", "150", "200"}));
}

TEST(Ticks, DegenerateAndNonFiniteRangesStillGiveAnAxis) {
  const TickSet flat = MakeTicks(5, 5, 5);
  EXPECT_LT(flat.values.front(), 5);
  EXPECT_GT(flat.values.back(), 5);
  const TickSet zero = MakeTicks(0, 0, 5);
  EXPECT_LT(zero.lo, 0);
  EXPECT_GT(zero.hi, 0);
  const TickSet nan = MakeTicks(NAN, 3, 5);
  EXPECT_EQ(nan.lo, 0);
  EXPECT_EQ(nan.hi, 1);
}

}  // namespace file_ticks_test
}  // namespace recruit::plot
