#include "common/rng.h"

#include <gtest/gtest.h>

#include <cmath>

namespace recruit {
namespace file_rng_test {

// Reference outputs of xoshiro256** from state {1, 2, 3, 4}, worked from the published
// algorithm: rotl(2 * 5, 7) * 9 = 11520, then 0, ...
TEST(Rng, MatchesXoshiro256StarStarReferenceSequence) {
  Rng r = Rng::FromState({1, 2, 3, 4});
  EXPECT_EQ(r(), 11520u);
  EXPECT_EQ(r(), 0u);
  EXPECT_EQ(r(), 1509978240u);
  EXPECT_EQ(r(), 1215971899390074240u);
}

TEST(Rng, SameSeedSameStreamDifferentSeedDifferentStream) {
  Rng a(42), b(42), c(43);
  for (int i = 0; i < 100; ++i) {
    const auto x = a();
    EXPECT_EQ(x, b());
    EXPECT_NE(x, c());
  }
}

TEST(Rng, UniformMeanAndVarianceWithinFiveSigma) {
  Rng r(7);
  const int n = 200000;
  double sum = 0, sum2 = 0;
  for (int i = 0; i < n; ++i) {
    const double u = r.Uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
    sum2 += u * u;
  }
  const double mean = sum / n, var = sum2 / n - mean * mean;
  // Var of the sample mean of U(0,1) is 1/(12 n).
  EXPECT_NEAR(mean, 0.5, 5 * std::sqrt(1.0 / 12 / n));
  EXPECT_NEAR(var, 1.0 / 12, 0.002);
}

TEST(Rng, DerivedSeedsDifferPerIndex) {
  EXPECT_NE(Rng::DeriveSeed(1, 0), Rng::DeriveSeed(1, 1));
  EXPECT_NE(Rng::DeriveSeed(1, 0), Rng::DeriveSeed(2, 0));
  EXPECT_EQ(Rng::DeriveSeed(5, 3), Rng::DeriveSeed(5, 3));
}

}  // namespace file_rng_test
}  // namespace recruit
