// WriteShortest against its reference, std::to_chars (shortest round-trip form): the same
// characters for random bit patterns (every exponent, subnormals, NaN, infinities), values of
// the sizes a filter writes, rounded and integer values, powers of ten and their neighbours.
#include "estimation/shortest_double.h"

#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>

namespace recruit {
namespace file_shortest_double_test {

std::string Reference(double v) {
  char buf[64];
  return std::string(buf, std::to_chars(buf, buf + sizeof buf, v).ptr);
}

std::string Fast(double v) {
  char buf[estimation::kShortestDoubleRoom + 8];
  std::memset(buf, '#', sizeof buf);
  char* end = estimation::WriteShortest(buf, v);
  EXPECT_LE(end - buf, estimation::kShortestDoubleMaxChars);
  for (int i = estimation::kShortestDoubleRoom; i < estimation::kShortestDoubleRoom + 8; ++i) {
    EXPECT_EQ(buf[i], '#') << "wrote past its room";
  }
  return std::string(buf, end);
}

TEST(EstimationShortestDouble, MatchesToCharsOnRandomBitPatterns) {
  std::mt19937_64 rng(1);
  for (int i = 0; i < 300000; ++i) {
    const uint64_t u = rng();
    double v;
    std::memcpy(&v, &u, sizeof v);
    ASSERT_EQ(Fast(v), Reference(v)) << "bits " << u;
  }
}

TEST(EstimationShortestDouble, MatchesToCharsOnFilterSizedValues) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int i = 0; i < 300000; ++i) {
    const double v = std::pow(10.0, -30.0 + 60.0 * U(rng)) * (U(rng) < 0.5 ? -1.0 : 1.0);
    for (double w : {v, std::round(v * 1e4) / 1e4, std::nearbyint(v), 60.0 * U(rng)}) {
      ASSERT_EQ(Fast(w), Reference(w)) << w;
    }
  }
}

TEST(EstimationShortestDouble, MatchesToCharsOnSpecialValues) {
  using L = std::numeric_limits<double>;
  for (double v : {0.0,
                   -0.0,
                   1.0,
                   -1.0,
                   0.5,
                   1e-5,
                   1e-4,
                   1e15,
                   1e16,
                   1e22,
                   1e23,
                   9007199254740992.0,
                   9007199254740993.0,
                   123456789012345678.0,
                   L::max(),
                   L::lowest(),
                   L::min(),
                   L::denorm_min(),
                   L::epsilon(),
                   L::infinity(),
                   -L::infinity(),
                   L::quiet_NaN()}) {
    EXPECT_EQ(Fast(v), Reference(v)) << v;
  }
  for (int k = -324; k <= 308; ++k) {
    const double p = std::pow(10.0, k);
    for (double v : {p, std::nextafter(p, 0.0), std::nextafter(p, L::infinity()), 3.0 * p, 7.0 * p,
                     1.25 * p, 9.999999 * p}) {
      ASSERT_EQ(Fast(v), Reference(v)) << v;
    }
  }
}

}  // namespace file_shortest_double_test
}  // namespace recruit
