// Output checks: the PNG decodes (lodepng, not cairo) at the requested size, the SVG is well
// formed XML of the requested size, and the band drawn spans exactly mean +- 2 sd on screen.
#include "plot/render.h"

#include <gtest/gtest.h>
#include <lodepng.h>

#include <cmath>
#include <regex>
#include <vector>

namespace recruit::plot {
namespace {

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

}  // namespace
}  // namespace recruit::plot
