// Layout rules: the legend never covers data (not the last 10 % of the x range, not any data
// point), stays on the canvas, and the figure is readable from 320 px wide to 4K.
#include "plot/layout.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace recruit::plot {
namespace file_layout_test {

// Data that end in the top right corner: where a legend inside the axes would usually sit.
Axes RampToTopRight(int n = 500) {
  Axes a;
  a.x_label = "time (s)";
  a.y_label = "force (N)";
  Series up{"force, a long legend label", {}, {}, {0.8, 0.1, 0.1}};
  Series ref{"reference", {}, {}, {0.3, 0.3, 0.3}, LineStyle::kDashed};
  Band band{"estimate ± 2 sd", {}, {}, {}, {1, 0.5, 0, 0.25}};
  for (int i = 0; i < n; ++i) {
    const double t = 200.0 * i / (n - 1);
    up.x.push_back(t), up.y.push_back(25 * t / 200 + std::sin(t));
    ref.x.push_back(t), ref.y.push_back(t < 100 ? 8 : 25);
    band.x.push_back(t), band.lo.push_back(up.y.back() - 1), band.hi.push_back(up.y.back() + 1);
  }
  a.series = {up, ref};
  a.bands = {band};
  return a;
}

Figure OnePanel() {
  return Figure{
      "task isometric_paper, estimator kalman-augmented, dT = 0.5 s, lambda = 0.2, seed 1",
      {RampToTopRight()}};
}

Figure FourPanels() {
  Figure f = OnePanel();
  for (int i = 0; i < 3; ++i) f.panels.push_back(RampToTopRight());
  return f;
}

const std::pair<double, double> kSizes[] = {{320, 240},   {480, 320},   {640, 480},  {1000, 600},
                                            {1920, 1080}, {3840, 2160}, {320, 1200}, {1000, 2200}};

void ExpectLegendClearOfData(const Figure& fig, double w, double h) {
  const FigureLayout f = ComputeLayout(fig, w, h);
  ASSERT_EQ(f.panels.size(), fig.panels.size());
  for (size_t i = 0; i < f.panels.size(); ++i) {
    const PanelLayout& p = f.panels[i];
    SCOPED_TRACE(::testing::Message() << w << "x" << h << " panel " << i);
    ASSERT_GT(p.legend.w, 0);
    ASSERT_GT(p.legend.h, 0);
    // Inside the canvas.
    EXPECT_GE(p.legend.x, 0);
    EXPECT_GE(p.legend.y, 0);
    EXPECT_LE(p.legend.right(), w);
    EXPECT_LE(p.legend.bottom(), h);
    for (const PanelLayout& q : f.panels) EXPECT_FALSE(p.legend.Intersects(q.data));
    // The last 10 % of the x range, over the whole data height.
    const Axes& a = fig.panels[i];
    const double x1 = a.series[0].x.back(), x0 = x1 - 0.1 * (x1 - a.series[0].x.front());
    const Rect tail{p.XToPx(x0), p.data.y, p.XToPx(x1) - p.XToPx(x0), p.data.h};
    EXPECT_FALSE(p.legend.Intersects(tail));
    for (const Series& s : a.series) {
      for (size_t k = 0; k < s.x.size(); ++k) {
        ASSERT_FALSE(p.legend.Contains(p.XToPx(s.x[k]), p.YToPx(s.y[k])))
            << s.label << " point " << k;
      }
    }
    // Every legend entry lies inside its box.
    for (const LegendItem& it : p.legend_items) {
      EXPECT_TRUE(p.legend.Contains(it.x, it.y)) << it.label;
      EXPECT_LE(it.x + f.swatch_px + f.pad + EstimateTextWidth(it.label, f.font_px),
                p.legend.right() + 1e-9)
          << it.label;
    }
  }
}

// A legend longer than its panel is tall (eight entries on a short canvas).
Figure ManyEntries() {
  Figure f = FourPanels();
  for (Axes& a : f.panels) {
    for (int i = 0; i < 6; ++i) {
      a.series.push_back(a.series[0]);
      a.series.back().label = "entry " + std::to_string(i);
    }
  }
  return f;
}

TEST(Layout, LegendNeverCoversDataAtAnySize) {
  for (const auto& [w, h] : kSizes) {
    ExpectLegendClearOfData(OnePanel(), w, h);
    ExpectLegendClearOfData(FourPanels(), w, 2.2 * h);
    // Four panels of eight entries need room: from 640 px wide (the command gives a narrower
    // combined figure a full height per panel).
    if (w >= 640) ExpectLegendClearOfData(ManyEntries(), w, 1.7 * h);
  }
}

TEST(Layout, DataCoversTheTickRangeAndTicksCoverTheData) {
  const FigureLayout f = ComputeLayout(OnePanel(), 1000, 600);
  const PanelLayout& p = f.panels[0];
  EXPECT_DOUBLE_EQ(p.XToPx(p.x_ticks.lo), p.data.x);
  EXPECT_DOUBLE_EQ(p.XToPx(p.x_ticks.hi), p.data.right());
  EXPECT_DOUBLE_EQ(p.YToPx(p.y_ticks.lo), p.data.bottom());
  const auto yr = DataRangeY(OnePanel().panels[0]);
  EXPECT_LE(p.y_ticks.lo, yr->lo);
  EXPECT_GE(p.y_ticks.hi, yr->hi);
}

void ExpectReadable(const Figure& fig, double w, double h) {
  SCOPED_TRACE(::testing::Message() << w << "x" << h);
  const FigureLayout f = ComputeLayout(fig, w, h);
  EXPECT_GE(f.font_px, kMinFontPx);
  EXPECT_GE(f.line_px, 1);
  EXPECT_GE(f.title_px, kMinFontPx);
  ASSERT_FALSE(f.title_lines.empty());
  std::string joined;
  for (const auto& line : f.title_lines) {
    EXPECT_LE(EstimateTextWidth(line, f.title_px), w) << line;  // the title stays on the canvas
    joined += (joined.empty() ? "" : " ") + line;
  }
  EXPECT_EQ(joined, fig.title);  // and loses nothing
  EXPECT_LE(f.title_lines.size() * f.title_px * 1.25, f.panels[0].data.y);
  for (const PanelLayout& p : f.panels) {
    EXPECT_GE(p.data.w, 0.55 * w);  // the data keep most of the width
    EXPECT_GE(p.data.h, 3 * f.font_px);
    EXPECT_GE(p.data.x, 0);
    EXPECT_LE(p.data.right(), w);
    EXPECT_LE(p.data.bottom(), h);
    // Tick labels do not collide: x labels fit their spacing, y ticks are >= 1.2 em apart.
    const double dx = p.data.w / (p.x_ticks.values.size() - 1);
    for (const auto& l : p.x_ticks.labels) EXPECT_LT(EstimateTextWidth(l, f.font_px), dx) << l;
    const double dy = p.data.h / (p.y_ticks.values.size() - 1);
    EXPECT_GE(dy, 1.2 * f.font_px);
    EXPECT_GE(p.x_ticks.values.size(), 2u);
    EXPECT_GE(p.y_ticks.values.size(), 2u);
  }
}

TEST(Layout, ReadableFrom320PxTo4K) {
  ExpectReadable(OnePanel(), 320, 240);
  ExpectReadable(OnePanel(), 1000, 600);
  ExpectReadable(OnePanel(), 3840, 2160);
  ExpectReadable(FourPanels(), 320, 700);
  ExpectReadable(FourPanels(), 3840, 4752);
}

TEST(Layout, TextAndLinesScaleWithTheCanvas) {
  const FigureLayout small = ComputeLayout(OnePanel(), 1000, 600);
  const FigureLayout big = ComputeLayout(OnePanel(), 3840, 2160);
  // At 4K the text is the same share of the width as at 1000 px (within 25 %), not 1000-px text
  // lost on a big canvas.
  const double ratio = (big.font_px / 3840) / (small.font_px / 1000);
  EXPECT_GT(ratio, 0.75);
  EXPECT_LT(ratio, 1.25);
  EXPECT_GE(big.line_px, 3 * small.line_px * 0.75);
  // At 320 px the floor holds, and the legend moves below the data.
  const FigureLayout tiny = ComputeLayout(OnePanel(), 320, 240);
  EXPECT_EQ(tiny.font_px, kMinFontPx);
  EXPECT_TRUE(tiny.legend_below);
  EXPECT_FALSE(big.legend_below);
}

}  // namespace file_layout_test
}  // namespace recruit::plot
