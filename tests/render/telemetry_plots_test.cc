// TelemetryPlots, one test per plot rule, without GL (Layout and Prepare are pure): the legend
// never overlaps a figure at any size from 320 px to 4K; ticks are 1-2-5 multiples whose printed
// labels read as exact values, never "-0"; a window much longer than
// mjvFigure's 1000 points keeps its start and its spikes; true counts are stairs, estimates are
// dashes in another colour, with est +- 2 sd as the band; angles in degrees.
#include "render/telemetry_plots.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>

#include "render/scene_renderer.h"
#include "test_model.h"

namespace recruit::render {
namespace file_telemetry_plots_test {

// A stand-in for MuJoCo's font: about what mjr_makeContext gives at `scale` percent (16 px high
// at 100 % is about 17 px; 18 keeps the test conservative), 0.55 em per character.
TextMetrics Metrics(int scale) {
  TextMetrics t;
  t.char_height = 18 * scale / 100;
  const int cw = std::max(1, t.char_height * 55 / 100);
  t.width = [cw](const std::string& s) { return static_cast<int>(s.size()) * cw; };
  return t;
}

TelemetrySample TwoBundles(double t, double rad_ref) {
  TelemetrySample s;
  s.time = t;
  s.reference_unit = "rad";
  s.reference = rad_ref;
  s.measured = 0.9 * rad_ref;
  for (const char* name : {"flexor", "extensor"}) {
    BundleTelemetry b;
    b.actuator = name;
    b.tendon_id = 0;
    b.true_on = static_cast<int>(t) % 13;
    b.estimated_on = b.true_on + 0.5;
    b.estimated_on_std = 1.5;
    b.force = 3 + t * 0.1;
    b.force_reference = 4;
    s.bundles.push_back(b);
  }
  return s;
}

bool Intersect(const mjrRect& a, const mjrRect& b) {
  return a.left < b.left + b.width && b.left < a.left + a.width && a.bottom < b.bottom + b.height &&
         b.bottom < a.bottom + a.height;
}
bool Inside(const mjrRect& in, const mjrRect& out) {
  return in.left >= out.left && in.bottom >= out.bottom &&
         in.left + in.width <= out.left + out.width &&
         in.bottom + in.height <= out.bottom + out.height;
}

TEST(TelemetryPlotsTest, LegendNeverOverlapsAFigureFrom320PxTo4K) {
  const int sizes[][2] = {{320, 240},  {480, 270},   {640, 360},   {640, 480},
                          {1280, 720}, {1920, 1080}, {2560, 1440}, {3840, 2160}};
  for (bool angle : {false, true}) {
    TelemetryPlots plots(20);
    for (int k = 0; k <= 300; ++k) {
      plots.Add(angle ? TwoBundles(0.1 * k, 0.5) : testing::Sample(0.1 * k, 0.5));
    }
    for (const auto& wh : sizes) {
      const int scale = FontScaleFor(wh[0], wh[1]);
      const TextMetrics text = Metrics(scale);
      // The plot column of SceneRenderer: the right 45 %, below the title line.
      const int side = wh[0] * 9 / 20;
      const mjrRect area = {wh[0] - side, 0, side, wh[1] - text.char_height * 3 / 2};
      const auto boxes = plots.Layout(area, text);
      int shown = 0;
      for (size_t p = 0; p < boxes.size(); ++p) {
        SCOPED_TRACE(std::to_string(wh[0]) + "x" + std::to_string(wh[1]) + " panel " +
                     std::to_string(p) + (angle ? " angle" : " force"));
        if (boxes[p].figure.height == 0) continue;
        ++shown;
        EXPECT_TRUE(Inside(boxes[p].legend, area));
        EXPECT_TRUE(Inside(boxes[p].figure, area));
        // Room for a title, x tick labels, the axis label and two grid intervals of a row each.
        EXPECT_GE(boxes[p].figure.height, 6 * text.char_height);
        for (const auto& other : boxes) {
          if (other.figure.height > 0) {
            EXPECT_FALSE(Intersect(boxes[p].legend, other.figure));
          }
        }
      }
      EXPECT_GE(shown, 2);  // the tracked quantity and the counts are always shown
      plots.Prepare(area, text);
      for (int p = 0; p < plots.num_panels(); ++p) {
        if (boxes[p].figure.height == 0) continue;
        EXPECT_EQ(plots.figure(p).flg_legend, 0);  // no legend inside the data area
        EXPECT_GE(plots.figure(p).gridsize[1], 3);
      }
    }
  }
}

// The 1-2-5 rule: step = m x 10^k with m in {1, 2, 5}.
bool RoundStep(double step) {
  const double k = std::floor(std::log10(step) + 1e-9);
  const double m = step / std::pow(10.0, k);
  return std::abs(m - 1) < 1e-6 || std::abs(m - 2) < 1e-6 || std::abs(m - 5) < 1e-6;
}

TEST(TelemetryPlotsTest, TicksAreRound125MultiplesAndPrintExactlyWithoutMinusZero) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> mag(-3, 4), u(0, 1);
  for (int trial = 0; trial < 300; ++trial) {
    const double scale = std::pow(10.0, mag(rng));
    const double offset = (u(rng) - 0.7) * scale;      // some ranges cross zero
    const double window = std::pow(10.0, 3 * u(rng));  // 1 .. 1000 s
    TelemetryPlots plots(window);
    const double t_end = window * (0.2 + 3 * u(rng));
    for (int k = 0; k <= 200; ++k) {
      TelemetrySample s = testing::Sample(t_end * k / 200, 0);
      s.reference = offset + scale * u(rng);
      s.measured = offset + scale * u(rng);
      plots.Add(s);
    }
    const mjrRect area = {0, 0, 200 + static_cast<int>(1500 * u(rng)),
                          200 + static_cast<int>(900 * u(rng))};
    plots.Prepare(area, Metrics(100));
    for (int axis = 0; axis < 2; ++axis) {
      const std::vector<double>& ticks = axis == 0 ? plots.x_ticks() : plots.y_ticks(0);
      ASSERT_GE(ticks.size(), 2u);
      const double step = ticks[1] - ticks[0];
      SCOPED_TRACE("trial " + std::to_string(trial) + " axis " + std::to_string(axis) + " step " +
                   std::to_string(step));
      EXPECT_TRUE(RoundStep(step));
      // x: what mjr_figure prints; y: what the plots print themselves.
      const std::vector<std::string> labels =
          axis == 0 ? TelemetryPlots::XTickLabels(plots.figure(0)) : plots.y_labels(0);
      ASSERT_EQ(labels.size(), ticks.size());
      for (size_t i = 0; i < ticks.size(); ++i) {
        const double k = ticks[i] / step;
        EXPECT_NEAR(k, std::round(k), 1e-6);  // an integer multiple of the step
        // The printed label reads back as the tick value (to float precision).
        EXPECT_NEAR(std::strtod(labels[i].c_str(), nullptr), ticks[i],
                    1e-5 * std::max(std::abs(ticks[i]), step))
            << labels[i];
        const bool minus_zero = labels[i].rfind("-0", 0) == 0 &&
                                labels[i].find_first_not_of("-0.") == std::string::npos;
        EXPECT_FALSE(minus_zero) << labels[i];
      }
    }
    // The y axis covers every plotted value; the x axis ends at or after now and spans the
    // window.
    const mjvFigure& f = plots.figure(0);
    for (int line = 0; line < 2; ++line) {
      for (int i = 0; i < f.linepnt[line]; ++i) {
        EXPECT_GE(f.linedata[line][2 * i + 1], f.range[1][0] - 1e-6 * scale);
        EXPECT_LE(f.linedata[line][2 * i + 1], f.range[1][1] + 1e-6 * scale);
      }
    }
    EXPECT_GE(plots.x_ticks().back(), t_end - 1e-9 * window);
    EXPECT_GE(plots.x_ticks().back() - plots.x_ticks().front(), window * (1 - 1e-9));
  }
}

TEST(TelemetryPlotsTest, LongWindowKeepsItsStartAndSpikesWithinTheFigureCap) {
  // 120 s at 30 frames/s = 3600 samples per line, over mjvFigure's 1000-point cap.
  const double window = 120;
  TelemetryPlots plots(window);
  for (int k = 0; k < 3600; ++k) {
    TelemetrySample s = testing::Sample(k / 30.0, 0);
    s.measured = k == 100 ? 50 : 10;  // one early one-frame spike
    plots.Add(s);
  }
  plots.Prepare({0, 0, 600, 400}, Metrics(100));
  const mjvFigure& f = plots.figure(0);
  ASSERT_EQ(plots.x_ticks().front(), 0.0);
  int measured = -1;  // which figure line holds the measured force (the solid line)
  for (int line = 0; line < mjMAXLINE; ++line) {
    if (f.linepnt[line] > 0 && f.linergb[line][0] == plots.lines(0)[1].rgb[0]) measured = line;
  }
  ASSERT_GE(measured, 0);
  const int n = f.linepnt[measured];
  EXPECT_LE(n, mjMAXLINEPNT);
  EXPECT_NEAR(f.linedata[measured][0], 0.0, 1e-6);  // the start is still there
  EXPECT_NEAR(f.linedata[measured][2 * (n - 1)], 3599 / 30.0, 1e-3);
  float peak = 0;
  for (int i = 0; i < n; ++i) peak = std::max(peak, f.linedata[measured][2 * i + 1]);
  // The spike survives the thinning (y values go to the figure mapped by the panel's axis).
  EXPECT_NEAR(plots.y_axis(0).FromUnit(peak), 50.0, 1e-5);
}

TEST(TelemetryPlotsTest, OldSamplesScrollOutAndTheAxisEndsOnATickAfterNow) {
  TelemetryPlots plots(10.0);
  for (int k = 0; k <= 300; ++k) plots.Add(testing::Sample(0.1 * k, 0.5));  // 0 .. 30 s
  plots.Prepare({0, 0, 600, 400}, Metrics(100));
  const std::vector<double>& x = plots.x_ticks();
  EXPECT_GE(x.back(), 30.0);
  EXPECT_LT(x.back() - 30.0, x[1] - x[0] + 1e-9);
  EXPECT_GE(x.back() - x.front(), 10.0);
  const mjvFigure& f = plots.figure(0);
  ASSERT_GT(f.linepnt[0], 0);
  EXPECT_GE(f.linedata[0][0], x.front() - 1e-6);
  EXPECT_FLOAT_EQ(f.range[0][0], static_cast<float>(x.front()));
  EXPECT_FLOAT_EQ(f.range[0][1], static_cast<float>(x.back()));
}

TEST(TelemetryPlotsTest, TrueCountIsStairsEstimateIsDashedInAnotherColourBandIsTwoSd) {
  TelemetryPlots plots(20.0);
  for (int k = 0; k <= 100; ++k) {
    TelemetrySample s = testing::Sample(0.1 * k, 0.2, /*true_on=*/k / 10, /*estimated_on=*/k / 9.0);
    s.bundles[0].estimated_on_std = 0.25 + 0.01 * k;
    plots.Add(s);
  }
  plots.Prepare({0, 0, 600, 400}, Metrics(100));
  const int counts = plots.num_panels() - 1;
  const mjvFigure& f = plots.figure(counts);
  const mjvFigure& d = plots.dashes(counts);
  // Stairs: every segment is horizontal or vertical.
  ASSERT_GT(f.linepnt[0], 10);
  for (int i = 1; i < f.linepnt[0]; ++i) {
    const float* a = f.linedata[0] + 2 * (i - 1);
    const float* b = f.linedata[0] + 2 * i;
    EXPECT_TRUE(a[0] == b[0] || a[1] == b[1]) << i;
  }
  // Dashes: isolated segments (barplot) with gaps between them, another colour.
  EXPECT_EQ(d.flg_barplot, 1);
  EXPECT_EQ(f.flg_barplot, 0);
  ASSERT_GE(d.linepnt[0], 4);
  EXPECT_LT(d.linedata[0][2], d.linedata[0][4]);  // a gap after the first dash
  const bool same = d.linergb[0][0] == f.linergb[0][0] && d.linergb[0][1] == f.linergb[0][1] &&
                    d.linergb[0][2] == f.linergb[0][2];
  EXPECT_FALSE(same);
  // The band: estimated_on -+ 2 estimated_on_std at every sample.
  const PlotBand& band = plots.bands(counts)[0];
  ASSERT_EQ(band.t.size(), 101u);
  for (size_t i = 0; i < band.t.size(); ++i) {
    const double est = static_cast<int>(i) / 9.0, sd = 0.25 + 0.01 * static_cast<int>(i);
    EXPECT_NEAR(band.lo[i], est - 2 * sd, 1e-12);
    EXPECT_NEAR(band.hi[i], est + 2 * sd, 1e-12);
  }
  // The y axis holds the band too, but a count axis starts at zero: the band's part below it
  // is clipped (est - 2 sd = -0.5 at the start).
  ASSERT_LT(band.lo.front(), 0.0);
  EXPECT_EQ(plots.y_axis(counts).lo, 0.0);
  EXPECT_EQ(plots.y_ticks(counts).front(), 0.0);
  EXPECT_GE(plots.y_axis(counts).hi, band.hi.back());
}

TEST(TelemetryPlotsTest, MissingEstimatesAreLeftOutAndAnglesAreInDegrees) {
  TelemetryPlots plots(20.0);
  TelemetrySample s = testing::Sample(1.0, 0.2, 7, std::nan(""));
  s.reference_unit = "rad";
  s.reference = M_PI / 6;
  s.measured = M_PI / 4;
  plots.Add(s);
  ASSERT_EQ(plots.num_panels(), 3);           // angle, bundle forces, counts
  EXPECT_EQ(plots.lines(2)[0].y.size(), 1u);  // true count
  EXPECT_EQ(plots.lines(2)[1].y.size(), 0u);  // NaN estimate: no point
  EXPECT_TRUE(plots.bands(2)[0].t.empty());
  EXPECT_NEAR(plots.lines(0)[0].y[0], 30.0, 1e-9);
  EXPECT_NEAR(plots.lines(0)[1].y[0], 45.0, 1e-9);
  plots.Prepare({0, 0, 800, 600}, Metrics(100));
  EXPECT_STREQ(plots.figure(0).title, "joint angle (deg)");
  EXPECT_STREQ(plots.figure(1).title, "bundle force (N)");
  EXPECT_STREQ(plots.figure(2).title, "units on");
}

TEST(FontScaleTest, GrowsWithTheFrameFrom50To300Percent) {
  EXPECT_EQ(FontScaleFor(320, 240), 50);
  EXPECT_EQ(FontScaleFor(640, 480), 100);
  EXPECT_EQ(FontScaleFor(640, 360), 100);
  EXPECT_EQ(FontScaleFor(1280, 720), 150);
  EXPECT_EQ(FontScaleFor(1920, 1080), 250);
  EXPECT_EQ(FontScaleFor(3840, 2160), 300);
  int last = 0;
  for (int w = 160; w <= 4096; w += 32) {
    const int s = FontScaleFor(w, w * 9 / 16);
    EXPECT_GE(s, last);
    last = s;
  }
}

}  // namespace file_telemetry_plots_test
}  // namespace recruit::render
