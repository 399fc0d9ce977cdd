#include "sim/reference.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "common/rng.h"

namespace recruit::sim {
namespace file_reference_test {

TEST(Reference, StepsHoldEachValueFromItsTime) {
  auto r = Reference::Steps(1.0, {2.0, 5.0}, {3.0, -1.0});
  ASSERT_TRUE(r.ok()) << r.error();
  EXPECT_DOUBLE_EQ((*r)(0.0), 1.0);
  EXPECT_DOUBLE_EQ((*r)(1.999), 1.0);
  EXPECT_DOUBLE_EQ((*r)(2.0), 3.0);  // the value after the jump at the jump
  EXPECT_DOUBLE_EQ((*r)(4.9), 3.0);
  EXPECT_DOUBLE_EQ((*r)(5.0), -1.0);
  EXPECT_DOUBLE_EQ((*r)(100.0), -1.0);
  const auto steps = r->Steps(10.0);
  ASSERT_EQ(steps.size(), 2u);
  EXPECT_DOUBLE_EQ(steps[0].time, 2.0);
  EXPECT_DOUBLE_EQ(steps[0].from, 1.0);
  EXPECT_DOUBLE_EQ(steps[0].to, 3.0);
  EXPECT_DOUBLE_EQ(steps[0].end, 5.0);
  EXPECT_DOUBLE_EQ(steps[1].end, 10.0);
}

TEST(Reference, RampInterpolatesLinearly) {
  auto r = Reference::FromJson(
      {{"type", "ramp"}, {"start", 1}, {"end", 3}, {"from", 0}, {"to", 10}}, "t.json.reference");
  ASSERT_TRUE(r.ok()) << r.error();
  EXPECT_DOUBLE_EQ((*r)(0.5), 0.0);
  EXPECT_DOUBLE_EQ((*r)(2.0), 5.0);
  EXPECT_DOUBLE_EQ((*r)(2.5), 7.5);
  EXPECT_DOUBLE_EQ((*r)(4.0), 10.0);
  EXPECT_TRUE(r->Steps(10).empty());
}

TEST(Reference, HoldEndsWhereARampBegins) {
  auto r = Reference::Piecewise({{0, 0}, {1, 0}, {1, 5}, {4, 5}, {6, 1}});
  ASSERT_TRUE(r.ok());
  const auto steps = r->Steps(10);
  ASSERT_EQ(steps.size(), 1u);
  EXPECT_DOUBLE_EQ(steps[0].end, 4.0);
}

TEST(Reference, PaperProfileSpansZeroToTwentyFiveNewtonsOver200Seconds) {
  const Reference r = Reference::PaperFig5();
  EXPECT_DOUBLE_EQ(r.MinValue(), 0.0);
  EXPECT_DOUBLE_EQ(r.MaxValue(), 25.0);
  EXPECT_DOUBLE_EQ(r.knots().back().t, 200.0);
  EXPECT_EQ(r.Steps(200).size(), 6u);
  EXPECT_DOUBLE_EQ(r(95.0), 16.5);  // halfway down the 25 -> 8 ramp over 80..110 s
}

TEST(Reference, DegreesScaleToRadians) {
  auto r = Reference::FromJson({{"type", "constant"}, {"value", 90}}, "x", M_PI / 180);
  ASSERT_TRUE(r.ok());
  EXPECT_DOUBLE_EQ((*r)(3.0), M_PI / 2);
}

TEST(Reference, BadInputsNameTheField) {
  auto a = Reference::FromJson({{"type", "sine"}}, "f.json.reference");
  ASSERT_FALSE(a.ok());
  EXPECT_NE(a.error().find("f.json.reference.type"), std::string::npos) << a.error();
  EXPECT_NE(a.error().find("allowed"), std::string::npos);
  auto b = Reference::FromJson({{"type", "steps"}, {"times", {1, 0.5}}, {"values", {1, 2}}}, "f");
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.error().find("strictly increasing"), std::string::npos) << b.error();
  auto c = Reference::FromJson({{"type", "piecewise"}, {"points", {{0, 1}, {2}}}}, "f");
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.error().find("[time, value]"), std::string::npos) << c.error();
  auto d = Reference::FromJson({{"type", "ramp"}, {"start", 3}, {"end", 1}, {"from", 0}, {"to", 1}},
                               "f");
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.error().find("f.end"), std::string::npos) << d.error();
}

// The same double, bit for bit (so a -0 is not a 0, and a NaN equals a NaN).
bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// A random reference: 1-8 knots at times on a coarse grid (so that some share a time: jumps,
// also at the first time), values from a small set with 0 and -0 among them (holds, ramps up
// and down, a -0 the interpolation must not turn into 0).
Reference RandomReference(Rng& rng) {
  const double values[] = {0.0, -0.0, 1.0, -2.5, 12.0, 24.0, 8.0, 1e-3};
  std::vector<Knot> knots;
  double t = -1 + 3 * std::floor(2 * rng.Uniform());  // -1 or 2
  const int n = 1 + static_cast<int>(8 * rng.Uniform());
  for (int i = 0; i < n; ++i) {
    const bool jump = i > 0 && rng.Uniform() < 0.4 &&
                      (i < 2 || knots[i - 1].t != knots[i - 2].t);  // at most two at a time
    if (!jump) t += 0.25 * std::ceil(8 * rng.Uniform());
    knots.push_back({t, values[static_cast<int>(8 * rng.Uniform())]});
  }
  return std::move(Reference::Piecewise(knots)).value();
}

// The cursor against the plain evaluation at every read, to the bit: on random references, at a
// run's accumulated physics-step times (t += h, as MuJoCo's clock goes), at every knot's time
// and its neighbouring doubles (reached from either side), then at random times in any order (going
// back, too), at the infinities and at NaN.
TEST(ReferenceCursor, EqualsThePlainEvaluationAtEveryRead) {
  Rng rng(19);
  constexpr double kInf = std::numeric_limits<double>::infinity();
  long reads = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const Reference r = RandomReference(rng);
    const double first = r.knots().front().t, last = r.knots().back().t;
    ReferenceCursor cursor(r);
    auto check = [&](double t) {
      const double want = r(t), got = cursor(t);
      ++reads;
      ASSERT_TRUE(SameBits(got, want))
          << "trial " << trial << " t " << t << ": " << got << " != " << want;
    };
    const double h = 0.002 + 0.01 * rng.Uniform();
    for (double t = first - 1; t < last + 1; t += h) check(t);
    for (const Knot& k : r.knots()) {  // each knot approached from below, then from above
      for (double side : {-kInf, kInf}) {
        check(std::nextafter(k.t, side));
        check(k.t);
        check(std::nextafter(k.t, -side));
      }
    }
    for (int k = 0; k < 200; ++k) check(first - 2 + (last - first + 4) * rng.Uniform());
    for (double t : {kInf, -kInf, std::nan(""), first, last, 0.0, -0.0}) check(t);
  }
  EXPECT_GT(reads, 100000);
}

}  // namespace file_reference_test
}  // namespace recruit::sim
