#include "sim/reference.h"

#include <gtest/gtest.h>

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

}  // namespace file_reference_test
}  // namespace recruit::sim
