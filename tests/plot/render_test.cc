// Output checks: the PNG decodes (lodepng, not cairo) at the requested size, the SVG is well
// formed XML of the requested size, the band drawn spans exactly mean +- 2 sd on screen, and a
// curve read back from the pixels through its grid lines and tick labels gives its values.
#include "plot/render.h"

#include <gtest/gtest.h>
#include <lodepng.h>

#include <algorithm>
#include <cmath>
#include <regex>
#include <vector>

namespace recruit::plot {
namespace file_render_test {

Figure BandFigure(double mean, double sd) {
  Axes a;
  a.x_label = "time (s)";
  a.y_label = "units on";
  a.y_range = Range{0, 20};
  Band band{"estimate ± 2 sd", {}, {}, {}, {0.9, 0.45, 0.0, 0.25}};
  Series est{"estimated", {}, {}, {0.9, 0.45, 0.0}, LineStyle::kDashed};
  for (int i = 0; i <= 100; ++i) {
    band.x.push_back(i), band.lo.push_back(mean - 2 * sd), band.hi.push_back(mean + 2 * sd);
    est.x.push_back(i), est.y.push_back(mean);
  }
  a.bands = {band};
  a.series = {est};
  return Figure{"band", {a}};
}

struct Image {
  unsigned w = 0, h = 0;
  std::vector<unsigned char> rgba;
  const unsigned char* At(int x, int y) const { return &rgba[4 * (size_t(y) * w + x)]; }
};

Image Decode(const std::string& png) {
  Image img;
  const unsigned err = lodepng::decode(
      img.rgba, img.w, img.h, reinterpret_cast<const unsigned char*>(png.data()), png.size());
  EXPECT_EQ(err, 0u) << lodepng_error_text(err);
  return img;
}

TEST(Render, PngDecodesAtTheRequestedSize) {
  for (const auto& [w, h] : {std::pair{320, 240}, {1000, 600}, {3840, 2160}}) {
    auto png = RenderFigure(BandFigure(10, 1), w, h, Format::kPng);
    ASSERT_TRUE(png.ok()) << png.error();
    const Image img = Decode(*png);
    EXPECT_EQ(img.w, unsigned(w));
    EXPECT_EQ(img.h, unsigned(h));
  }
}

// A minimal well-formedness check: every tag closes in order, one root element named svg.
void ExpectWellFormedSvg(const std::string& xml, int w, int h) {
  ASSERT_EQ(xml.rfind("<?xml", 0), 0u);
  std::vector<std::string> stack;
  int roots = 0;
  size_t i = 0;
  while ((i = xml.find('<', i)) != std::string::npos) {
    const size_t end = xml.find('>', i);
    ASSERT_NE(end, std::string::npos) << "unclosed '<' at " << i;
    const std::string tag = xml.substr(i + 1, end - i - 1);
    i = end + 1;
    if (tag[0] == '?' || tag[0] == '!') continue;  // declaration, comment
    if (tag[0] == '/') {
      ASSERT_FALSE(stack.empty()) << "</" << tag << "> without an open tag";
      ASSERT_EQ(tag.substr(1), stack.back());
      stack.pop_back();
      continue;
    }
    const std::string name = tag.substr(0, tag.find_first_of(" \t\n/"));
    if (stack.empty()) {
      ++roots;
      EXPECT_EQ(name, "svg");
      std::smatch m;
      ASSERT_TRUE(std::regex_search(tag, m, std::regex("width=\"([0-9.]+)px\"")));
      EXPECT_DOUBLE_EQ(std::stod(m[1]), w);
      ASSERT_TRUE(std::regex_search(tag, m, std::regex("height=\"([0-9.]+)px\"")));
      EXPECT_DOUBLE_EQ(std::stod(m[1]), h);
    }
    if (tag.back() != '/') stack.push_back(name);
  }
  EXPECT_TRUE(stack.empty()) << stack.size() << " tags left open";
  EXPECT_EQ(roots, 1);
}

TEST(Render, SvgIsWellFormedAtTheRequestedSize) {
  auto svg = RenderFigure(BandFigure(10, 1), 1000, 600, Format::kSvg);
  ASSERT_TRUE(svg.ok()) << svg.error();
  ExpectWellFormedSvg(*svg, 1000, 600);
}

// The band is the only orange-tinted fill: pixels with blue well below red.
bool Tinted(const unsigned char* p) { return int(p[0]) - int(p[2]) > 25; }

TEST(Render, BandSpansMeanPlusMinusTwoSd) {
  const double mean = 9, sd = 1.5;  // band 6 .. 12 on a 0 .. 20 axis
  const Figure fig = BandFigure(mean, sd);
  auto png = RenderFigure(fig, 1000, 600, Format::kPng);
  ASSERT_TRUE(png.ok());
  const Image img = Decode(*png);
  const PanelLayout p = LayoutWithCairoText(fig, 1000, 600).panels[0];
  // A column away from the legend and the grid lines: a quarter into the data.
  const int x = static_cast<int>(p.XToPx(23.7));
  int top = -1, bottom = -1;
  for (int y = static_cast<int>(p.data.y) + 1; y < static_cast<int>(p.data.bottom()); ++y) {
    if (Tinted(img.At(x, y))) {
      if (top < 0) top = y;
      bottom = y;
    }
  }
  ASSERT_GE(top, 0) << "no band drawn";
  // Pixel rows cover [row, row + 1): compare the band's edges with 1 px of antialiasing.
  EXPECT_NEAR(top, p.YToPx(mean + 2 * sd), 1.0);
  EXPECT_NEAR(bottom + 1, p.YToPx(mean - 2 * sd), 1.0);
}

TEST(Render, NoBandWithoutAStandardDeviation) {
  Figure fig = BandFigure(9, 1.5);
  for (double& v : fig.panels[0].bands[0].lo) v = NAN;
  auto png = RenderFigure(fig, 1000, 600, Format::kPng);
  ASSERT_TRUE(png.ok());
  const Image img = Decode(*png);
  const PanelLayout p = LayoutWithCairoText(fig, 1000, 600).panels[0];
  const int x = static_cast<int>(p.XToPx(23.7));
  int tinted = 0;
  for (int y = static_cast<int>(p.data.y) + 1; y < static_cast<int>(p.data.bottom()); ++y) {
    tinted += Tinted(img.At(x, y));
  }
  EXPECT_LE(tinted, 4);  // the dashed estimate line only (about 2 px thick)
}

// Runs of consecutive rows whose weight is > 0 -> the weighted centre of each run.
std::vector<double> Centres(const std::vector<double>& weight, int y0) {
  std::vector<double> c;
  for (size_t i = 0; i < weight.size();) {
    if (weight[i] <= 0) {
      ++i;
      continue;
    }
    double sum = 0, wsum = 0;
    for (; i < weight.size() && weight[i] > 0; ++i)
      sum += (y0 + double(i)) * weight[i], wsum += weight[i];
    c.push_back(sum / wsum);
  }
  return c;
}

bool Grey(const unsigned char* p) {
  return std::abs(p[0] - p[1]) < 6 && std::abs(p[1] - p[2]) < 6 && p[0] < 248;
}

// A plateau signal over a long run: 12 levels of `unit` above `offset`, 10 s each.
double Level(double t, double unit, double offset) {
  static const int pattern[] = {0, 3, 3, 1, 6, 2, 9, 4, 0, 7, 5, 8};
  return offset + unit * pattern[static_cast<int>(std::floor(t / 10)) % 12];
}

TEST(Render, CurvesSitWhereTheirTickLabelsSayOverChangingRanges) {
  const Color blue{0.0, 0.45, 0.70};
  // (unit, offset, band sd, run start): ranges across zero, far from zero, small, and counts
  // (>= 0) whose band reaches below zero, over different stretches of a long run.
  const double cases[][4] = {{10, -15, 0, 0}, {11, -45, 0, 40}, {0.02, 3.5, 0, 100},
                             {4, 0, 5, 0},    {4, 2, 9, 60},    {250, 1000, 0, 20}};
  for (const auto& c : cases) {
    SCOPED_TRACE(::testing::Message() << "unit " << c[0] << " offset " << c[1] << " sd " << c[2]);
    Axes a;
    a.x_label = "time (s)";
    a.y_label = "value";
    Series s{"value", {}, {}, blue};
    Band band{"± 2 sd", {}, {}, {}, {0.9, 0.45, 0.0, 0.25}};
    for (int i = 0; i <= 2000; ++i) {
      const double t = c[3] + 0.05 * i;  // 100 s at 20 samples/s
      s.x.push_back(t), s.y.push_back(Level(t, c[0], c[1]));
      band.x.push_back(t), band.lo.push_back(s.y.back() - 2 * c[2]);
      band.hi.push_back(s.y.back() + 2 * c[2]);
    }
    a.series = {s};
    if (c[2] > 0) a.bands = {band};
    const Figure fig{"", {a}};
    auto png = RenderFigure(fig, 1000, 600, Format::kPng);
    ASSERT_TRUE(png.ok()) << png.error();
    const Image img = Decode(*png);
    const FigureLayout f = LayoutWithCairoText(fig, 1000, 600);
    const PanelLayout& p = f.panels[0];
    const std::vector<double>& ticks = p.y_ticks.values;
    // Grid lines (and the frame at the axis ends): rows grey across a tenth of the data width or
    // more (the band may tint the rest).
    const int x0 = int(p.data.x) + 2, x1 = int(p.data.right()) - 2;
    const int y0 = int(p.data.y) - 2, y1 = int(p.data.bottom()) + 2;
    std::vector<double> grid_w(y1 - y0 + 1), text_w(y1 - y0 + 1);
    for (int y = y0; y <= y1; ++y) {
      int n = 0;
      double dark = 0;
      for (int x = x0; x <= x1; ++x) {
        if (Grey(img.At(x, y))) ++n, dark += 255 - img.At(x, y)[0];
      }
      grid_w[y - y0] = n > (x1 - x0) / 10 ? dark / n : 0;
      // Tick labels end at data.x - pad: their last glyph lies in a half-em strip before it.
      for (int x = int(p.data.x - f.pad - 0.5 * f.font_px); x < int(p.data.x - f.pad); ++x) {
        const unsigned char* q = img.At(x, y);
        if (q[0] < 150) text_w[y - y0] += 255 - q[0];
      }
    }
    const std::vector<double> grid = Centres(grid_w, y0), text = Centres(text_w, y0);
    ASSERT_EQ(grid.size(), ticks.size());
    ASSERT_EQ(text.size(), ticks.size());
    for (size_t i = 0; i < ticks.size(); ++i) {
      // Rows grow downwards: the last grid row is the lowest tick.
      EXPECT_NEAR(text[i], grid[i], 0.3 * f.font_px) << p.y_ticks.labels[ticks.size() - 1 - i];
    }
    // Counts (>= 0) with a band reaching below zero: the axis starts at 0.
    if (c[2] > 0) {
      EXPECT_EQ(ticks.front(), 0.0);
    }
    // The curve at plateau columns, read through the grid rows and tick values.
    int checked = 0;
    for (int x = x0 + 5; x < x1 - 5; x += 11) {
      const double t =
          p.x_ticks.lo + (x + 0.5 - p.data.x) / p.data.w * (p.x_ticks.hi - p.x_ticks.lo);
      const double v = Level(t, c[0], c[1]), hold = 0.3;
      if (t > s.x.back() || Level(t - hold, c[0], c[1]) != v || Level(t + hold, c[0], c[1]) != v)
        continue;
      double sum = 0, wsum = 0;
      for (int y = y0; y <= y1; ++y) {
        const unsigned char* q = img.At(x, y);
        const double w = std::max(0, 120 - std::abs(q[0] - 0) - std::abs(q[2] - 178) / 2);
        if (q[2] > q[0] + 60) sum += (y + 0.5) * w, wsum += w;
      }
      if (wsum == 0) continue;
      const double row = sum / wsum;
      const double read = ticks.back() + (row - grid.front() - 0.5) / (grid.back() - grid.front()) *
                                             (ticks.front() - ticks.back());
      const double px_per_unit = (grid.back() - grid.front()) / (ticks.back() - ticks.front());
      EXPECT_NEAR(read, v, 1.5 / px_per_unit) << "t " << t;
      ++checked;
    }
    EXPECT_GT(checked, 10);
  }
}

}  // namespace file_render_test
}  // namespace recruit::plot
