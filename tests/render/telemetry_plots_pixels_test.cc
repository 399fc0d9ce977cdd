// TelemetryPlots read back from the rendered pixels (OSMesa): over long runs whose data range
// changes, at every still time of a render, each panel's curve sits where its tick labels say.
// The references are independent of the plotting code: the grid lines' pixel rows (drawn by
// mjr_figure at the ticks), the rows and widths of the label text (drawn by the plots), and the
// value the test itself put into a curve. Count axes start at zero.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "plot/ticks.h"
#include "render/gl_context.h"
#include "render/scene_renderer.h"
#include "render/telemetry_plots.h"
#include "test_model.h"

namespace recruit::render {
namespace file_telemetry_plots_pixels_test {

struct Image {
  int w = 0, h = 0;
  std::vector<unsigned char> rgb;  // rows bottom-up (mjr_readPixels)
  const unsigned char* at(int x, int y) const { return rgb.data() + 3 * (size_t(y) * w + x); }
};

bool Near(const unsigned char* p, const float rgb[3], int tol) {
  for (int c = 0; c < 3; ++c) {
    if (std::abs(p[c] - static_cast<int>(std::lround(255 * rgb[c]))) > tol) return false;
  }
  return true;
}

// Runs of consecutive true rows -> the centre of each run.
std::vector<double> RunCentres(const std::vector<bool>& rows, int lo) {
  std::vector<double> c;
  for (size_t y = 0; y < rows.size();) {
    if (!rows[y]) {
      ++y;
      continue;
    }
    size_t e = y;
    while (e < rows.size() && rows[e]) ++e;
    c.push_back(lo + 0.5 * (y + e - 1));
    y = e;
  }
  return c;
}

// One GL context and MuJoCo render context for a frame size (OSMesa), drawing only the plots.
class PlotCanvas {
 public:
  PlotCanvas(int w, int h) : w_(w), h_(h) {
    auto gl = GlContext::Create(GlBackend::kOsMesa, w, h);
    EXPECT_TRUE(gl.ok()) << gl.error();
    if (!gl.ok()) return;
    gl_ = std::move(*gl);
    model_ = testing::LoadXml(testing::kArmXml);
    model_->vis.global.offwidth = w;
    model_->vis.global.offheight = h;
    model_->vis.quality.offsamples = 0;  // exact colours: no blended edges to tell apart
    mjr_defaultContext(&con_);
    mjr_makeContext(model_.get(), &con_, FontScaleFor(w, h));
    mjr_setBuffer(mjFB_OFFSCREEN, &con_);
    ok_ = true;
  }
  ~PlotCanvas() {
    if (ok_) mjr_freeContext(&con_);
  }
  bool ok() const { return ok_; }
  const mjrContext& context() const { return con_; }

  // The plot column of SceneRenderer: the right 45 % below a title line.
  mjrRect Column() const {
    const int below = h_ - (con_.charHeight + con_.charHeight / 2);
    const int side = w_ * 9 / 20;
    return {w_ - side, 0, side, below};
  }
  Image Draw(TelemetryPlots& plots) {
    (void)gl_->MakeCurrent();
    mjr_setBuffer(mjFB_OFFSCREEN, &con_);
    mjr_rectangle({0, 0, w_, h_}, 0.05f, 0.05f, 0.08f, 1.f);
    plots.Draw(Column(), &con_);
    Image img{w_, h_, std::vector<unsigned char>(size_t(w_) * h_ * 3)};
    mjr_readPixels(img.rgb.data(), nullptr, {0, 0, w_, h_}, &con_);
    return img;
  }

 private:
  int w_, h_;
  bool ok_ = false;
  std::unique_ptr<GlContext> gl_;
  ModelPtr model_;
  mjrContext con_;
};

// The horizontal grid lines of a figure (drawn without multisampling, so in the grid colour
// exactly): the centre of each run of rows that are grid-coloured across a tenth of the pane
// or more (curves, dashes and bands may cover the rest).
std::vector<double> GridRows(const Image& img, const mjvFigure& f) {
  const int x0 = f.xaxispixel[0] + 2, x1 = f.xaxispixel[1] - 2;
  const int y0 = f.yaxispixel[0] - 3, y1 = f.yaxispixel[1] + 3;
  std::vector<bool> rows(y1 - y0 + 1);
  for (int y = y0; y <= y1; ++y) {
    int n = 0;
    for (int x = x0; x <= x1; ++x) n += Near(img.at(x, y), f.gridrgb, 3);
    rows[y - y0] = n > (x1 - x0 + 1) / 10;
  }
  return RunCentres(rows, y0);
}

struct TextRun {
  double centre;
  int left;  // leftmost text pixel
};

// The y tick labels: runs of rows with text-coloured pixels left of the pane, inside the
// figure's box (the legend strips are outside it).
std::vector<TextRun> LabelRuns(const Image& img, const mjvFigure& f, const mjrRect& box) {
  const int left = box.left, right = f.xaxispixel[0] - 2;
  const int y0 = box.bottom, y1 = box.bottom + box.height - 1;
  std::vector<bool> rows(y1 - y0 + 1);
  for (int y = y0; y <= y1; ++y) {
    for (int x = left; x <= right && !rows[y - y0]; ++x) {
      const unsigned char* p = img.at(x, y);
      rows[y - y0] = p[0] > 140 && p[1] > 140 && p[2] > 140;
    }
  }
  std::vector<TextRun> runs;
  for (double c : RunCentres(rows, y0)) {
    int lx = right;
    const int half = 3;
    for (int y = static_cast<int>(c) - half; y <= static_cast<int>(c) + half; ++y) {
      for (int x = left; x <= right; ++x) {
        const unsigned char* p = img.at(x, y);
        if (p[0] > 140 && p[1] > 140 && p[2] > 140) lx = std::min(lx, x);
      }
    }
    runs.push_back({c, lx});
  }
  return runs;
}

// The mean row of a colour in a pixel column of the pane (-1 if absent).
double CurveRow(const Image& img, const mjvFigure& f, int x, const std::array<float, 3>& rgb) {
  double sum = 0;
  int n = 0;
  for (int y = f.yaxispixel[0] - 2; y <= f.yaxispixel[1] + 2; ++y) {
    if (Near(img.at(x, y), rgb.data(), 24)) sum += y, ++n;
  }
  return n ? sum / n : -1;
}

// A plateau signal: value k * `unit` on [k * len, (k + 1) * len) for a pattern that moves the
// range up and down (and across zero when `offset` < 0).
double Plateau(double t, double len, double unit, double offset) {
  static const int pattern[] = {0, 3, 3, 1, 6, 2, 9, 4, 0, 7, 5, 8};
  const int k = static_cast<int>(std::floor(t / len));
  return offset + unit * pattern[((k % 12) + 12) % 12];  // t < 0 (before the window) too
}

struct Case {
  int w, h;
  double window, fps, duration, still_every;
};

// An angle task (three panels: angle, bundle forces, counts) whose ranges change over the run.
TelemetrySample AngleSample(double t) {
  TelemetrySample s;
  s.time = t;
  s.reference_unit = "rad";
  s.reference = Plateau(t, 10, 10, 0) * M_PI / 180;  // 0 .. 90 deg, e.g. 0 then 30
  s.measured = Plateau(t, 7, 11, -15) * M_PI / 180;  // -15 .. 84 deg
  for (int b = 0; b < 2; ++b) {
    BundleTelemetry bt;
    bt.actuator = b ? "extensor" : "flexor";
    bt.force = Plateau(t + 3 * b, 6, 2.5, 0);
    bt.force_reference = 5;
    // 2 .. 38 units: the line stays off the axis ends, where half of it would be clipped.
    bt.true_on = static_cast<int>(Plateau(t + 5 * b, 9, 4, 2));
    bt.estimated_on = bt.true_on + 3;            // the dashes stay off the true count
    bt.estimated_on_std = 4 + bt.true_on / 4.0;  // the band reaches below zero
    s.bundles.push_back(bt);
  }
  return s;
}

void CheckPanel(
    const Image& img, const TelemetryPlots& plots, int p, const PlotCanvas& canvas,
    const std::vector<std::pair<std::array<float, 3>, std::function<double(double)>>>& curves,
    double sample_dt, const std::string& where) {
  SCOPED_TRACE(where + " panel " + std::to_string(p));
  const mjvFigure& f = plots.figure(p);
  const std::vector<double>& ticks = plots.y_ticks(p);
  const std::vector<std::string>& labels = plots.y_labels(p);
  ASSERT_GE(ticks.size(), 2u);
  ASSERT_EQ(labels.size(), ticks.size());
  // The grid: one line per tick.
  const std::vector<double> grid = GridRows(img, f);
  // The labels: one per tick, centred on its grid line, as wide as its own text.
  const mjrContext& con = canvas.context();
  const TextMetrics text = TextMetrics::FromContext(&con);
  const mjrRect box = plots.Layout(canvas.Column(), text)[p].figure;
  const std::vector<TextRun> runs = LabelRuns(img, f, box);
  ASSERT_EQ(runs.size(), ticks.size());
  const int right = f.xaxispixel[0] - con.charHeight / 3;
  for (size_t i = 0; i < ticks.size(); ++i) {
    EXPECT_NEAR(runs[i].centre, grid[i], con.charHeight / 4.0) << labels[i];
    const int width = right - runs[i].left;
    EXPECT_NEAR(width, text.width(labels[i]), con.charWidth[static_cast<unsigned char>('0')] * 0.6)
        << labels[i];
    EXPECT_DOUBLE_EQ(std::strtod(labels[i].c_str(), nullptr), ticks[i]);
  }
  // Each curve, read at plateau columns through the grid rows and the tick values, gives the
  // value the test put in.
  const double t0 = f.xaxisdata[0], t1 = f.xaxisdata[1];
  const int x0 = f.xaxispixel[0], x1 = f.xaxispixel[1];
  for (const auto& [rgb, value] : curves) {
    int checked = 0;
    for (int x = x0 + 4; x <= x1 - 4; x += 7) {
      const double t = t0 + (x - x0) / double(x1 - x0) * (t1 - t0);
      // 3 px and a sample interval either side (curves are straight between samples): the same
      // plateau.
      const double dt = 3.0 * (t1 - t0) / (x1 - x0) + sample_dt;
      const double v = value(t);
      if (t > plots.lines(0)[0].t.back() || value(t - dt) != v || value(t + dt) != v) continue;
      const double row = CurveRow(img, f, x, rgb);
      if (row < 0) continue;  // hidden under another curve
      const double read = ticks.front() + (row - grid.front()) / (grid.back() - grid.front()) *
                                              (ticks.back() - ticks.front());
      const double px_per_unit = (grid.back() - grid.front()) / (ticks.back() - ticks.front());
      EXPECT_NEAR(read, v, 2.0 / px_per_unit) << "t " << t;
      ++checked;
    }
    EXPECT_GT(checked, 3);
  }
}

TEST(TelemetryPlotsPixelsTest, CurvesSitWhereTheirTickLabelsSayAtEveryStill) {
  const Case cases[] = {{640, 480, 20, 10, 120, 5},
                        {1280, 720, 20, 5, 120, 10},
                        {1280, 720, 10, 5, 60, 2.5},
                        {3840, 2160, 20, 2, 60, 20}};
  int forces_checked = 0;
  for (const Case& c : cases) {
    PlotCanvas canvas(c.w, c.h);
    ASSERT_TRUE(canvas.ok());
    TelemetryPlots plots(c.window);
    double next_still = c.still_every;
    const int frames = static_cast<int>(std::lround(c.duration * c.fps));
    for (int k = 0; k <= frames; ++k) {
      const double t = k / c.fps;
      plots.Add(AngleSample(t));
      if (t + 1e-9 < next_still) continue;
      next_still += c.still_every;
      const Image img = canvas.Draw(plots);
      const std::string where = std::to_string(c.w) + "x" + std::to_string(c.h) + " window " +
                                std::to_string(c.window) + " t " + std::to_string(t);
      const std::array<float, 3> red = plots.lines(0)[1].rgb;
      CheckPanel(img, plots, 0, canvas,
                 {{red, [](double t) { return AngleSample(t).measured * 180 / M_PI; }}}, 1 / c.fps,
                 where);
      // The bundle forces, when the frame is tall enough for them.
      const TextMetrics text = TextMetrics::FromContext(&canvas.context());
      if (plots.Layout(canvas.Column(), text)[1].figure.height > 0) {
        ++forces_checked;
        const std::array<float, 3> flexor = plots.lines(1)[0].rgb;
        CheckPanel(img, plots, 1, canvas,
                   {{flexor, [](double t) { return AngleSample(t).bundles[0].force; }}}, 1 / c.fps,
                   where);
      }
      const int counts = plots.num_panels() - 1;
      const std::array<float, 3> flexor = plots.lines(counts)[0].rgb;
      CheckPanel(img, plots, counts, canvas,
                 {{flexor, [](double t) { return double(AngleSample(t).bundles[0].true_on); }}},
                 1 / c.fps, where);
      // Count axes start at zero, however far below zero the band reaches.
      EXPECT_EQ(plots.y_ticks(counts).front(), 0.0) << where;
      if (::testing::Test::HasFailure()) return;
    }
  }
  EXPECT_GT(forces_checked, 0);  // the 4K frame shows all three panels
}

}  // namespace file_telemetry_plots_pixels_test
}  // namespace recruit::render
