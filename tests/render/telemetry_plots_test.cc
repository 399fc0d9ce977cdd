// TelemetryPlots against hand-computed windows: which points remain after scrolling, the x range,
// NaN estimates left out, angles converted to degrees.
#include "render/telemetry_plots.h"

#include <gtest/gtest.h>

#include <cmath>

#include "test_model.h"

namespace recruit::render {
namespace {

TEST(TelemetryPlotsTest, ScrollsToTheLastWindowSeconds) {
  TelemetryPlots plots(10.0);
  for (int k = 0; k <= 300; ++k) plots.Add(testing::Sample(0.1 * k, 0.5));  // 0 .. 30 s
  const mjvFigure& f = plots.tracking();
  // Points at t >= 20 s remain: 20.0, 20.1, ..., 30.0 (101 points; float rounding at 20.0 may
  // keep or drop the first).
  EXPECT_NEAR(f.linepnt[0], 101, 1);
  EXPECT_GE(f.linedata[0][0], 20.0f - 1e-3f);
  EXPECT_FLOAT_EQ(f.linedata[0][2 * (f.linepnt[0] - 1)], 30.0f);
  EXPECT_FLOAT_EQ(f.range[0][0], 20.0f);
  EXPECT_FLOAT_EQ(f.range[0][1], 30.0f);
  EXPECT_FLOAT_EQ(f.linedata[0][1], 12.0f);  // reference, N
  EXPECT_FLOAT_EQ(f.linedata[1][1], 11.0f);  // measured, N
}

TEST(TelemetryPlotsTest, EarlyWindowStartsAtZero) {
  TelemetryPlots plots(20.0);
  plots.Add(testing::Sample(3.0, 0));
  EXPECT_FLOAT_EQ(plots.tracking().range[0][0], 0.0f);
  EXPECT_FLOAT_EQ(plots.tracking().range[0][1], 20.0f);
}

TEST(TelemetryPlotsTest, MissingEstimatesAreLeftOutAndAnglesAreInDegrees) {
  TelemetryPlots plots(20.0);
  TelemetrySample s = testing::Sample(1.0, 0.2, 7, std::nan(""));
  s.reference_unit = "rad";
  s.reference = M_PI / 6;
  s.measured = M_PI / 4;
  plots.Add(s);
  EXPECT_EQ(plots.recruitment().linepnt[0], 1);  // true count
  EXPECT_EQ(plots.recruitment().linepnt[1], 0);  // NaN estimate: no point
  EXPECT_FLOAT_EQ(plots.recruitment().linedata[0][1], 7.0f);
  EXPECT_NEAR(plots.tracking().linedata[0][1], 30.0f, 1e-4);
  EXPECT_NEAR(plots.tracking().linedata[1][1], 45.0f, 1e-4);
  EXPECT_STREQ(plots.tracking().title, "joint angle (deg)");
}

TEST(TelemetryPlotsTest, KeepsAtMostTheFiguresPointCapacity) {
  TelemetryPlots plots(1e6);  // nothing scrolls out by time
  for (int k = 0; k < 1500; ++k) plots.Add(testing::Sample(0.001 * k, 0));
  EXPECT_EQ(plots.tracking().linepnt[0], mjMAXLINEPNT);
  // The oldest 1500 - mjMAXLINEPNT samples were dropped (mjMAXLINEPNT is 1001 in MuJoCo 3).
  EXPECT_FLOAT_EQ(plots.tracking().linedata[0][0], 0.001f * (1500 - mjMAXLINEPNT));
}

}  // namespace
}  // namespace recruit::render
