// SceneRenderer against independent references: pixel statistics for "not blank", a pinhole
// projection of the tendon for where its colour must change, byte equality for determinism.
#include "render/scene_renderer.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <set>
#include <vector>

#include "render/tendon_heat.h"
#include "test_model.h"

namespace recruit::render {
namespace file_scene_renderer_test {

using testing::DataPtr;
using ::testing::HasSubstr;
using testing::LoadXml;
using testing::ModelPtr;
using testing::Sample;

class SceneRendererTest : public ::testing::Test {
 protected:
  void SetUp() override {
    m_ = LoadXml(testing::kArmXml);
    ASSERT_NE(m_, nullptr);
    d_.reset(mj_makeData(m_.get()));
    mj_forward(m_.get(), d_.get());
  }

  std::vector<unsigned char> Render(const RenderOptions& options, const TelemetrySample* s) {
    auto r = SceneRenderer::Create(m_.get(), options, RunLabel{"test", "kalman", 0.5, 0.2, 1});
    EXPECT_TRUE(r.ok()) << r.error();
    if (!r.ok()) return {};
    std::vector<unsigned char> rgb(static_cast<size_t>(options.width) * options.height * 3);
    if (s) (*r)->AddPlotPoint(*s);
    Status st = (*r)->Render(m_.get(), d_.get(), s, rgb.data());
    EXPECT_TRUE(st.ok()) << st.error();
    last_recoloured_ = (*r)->last_recoloured_geoms();
    return rgb;
  }

  ModelPtr m_;
  DataPtr d_;
  int last_recoloured_ = 0;
};

RenderOptions Front(int w = 640, int h = 480) {
  RenderOptions o;
  o.width = w;
  o.height = h;
  o.camera.name = "front";
  return o;
}

TEST_F(SceneRendererTest, HeadlessFrameIsNotBlank) {
  const TelemetrySample s = Sample(1.0, 0.5);
  const std::vector<unsigned char> rgb = Render(Front(), &s);
  ASSERT_EQ(rgb.size(), 640u * 480 * 3);
  // Reference: a blank (cleared) frame has one colour and zero variance. A drawn scene with
  // floor, arm, tendon, plots and text has many colours and a wide spread of brightness.
  std::set<int> colours;
  double sum = 0, sum2 = 0;
  const size_t n = rgb.size() / 3;
  for (size_t i = 0; i < n; ++i) {
    const int c = rgb[3 * i] << 16 | rgb[3 * i + 1] << 8 | rgb[3 * i + 2];
    colours.insert(c);
    const double y = (rgb[3 * i] + rgb[3 * i + 1] + rgb[3 * i + 2]) / 3.0;
    sum += y;
    sum2 += y * y;
  }
  const double mean = sum / n, stddev = std::sqrt(sum2 / n - mean * mean);
  EXPECT_GT(colours.size(), 200u);
  EXPECT_GT(stddev, 20.0);
  EXPECT_GT(mean, 10.0);
  EXPECT_LT(mean, 245.0);
}

TEST_F(SceneRendererTest, TendonTurnsFromBlueToRedWhereThePinholeModelPutsIt) {
  RenderOptions o = Front();
  o.figures = false;  // only the tendon may differ between the two renders
  o.text_panel = false;
  o.labels = false;
  o.heat_key = false;
  const TelemetrySample cold = Sample(1.0, 0.0), hot = Sample(1.0, 1.0);
  const std::vector<unsigned char> a = Render(o, &cold);
  EXPECT_GT(last_recoloured_, 0);
  const std::vector<unsigned char> b = Render(o, &hot);
  ASSERT_EQ(a.size(), b.size());

  // Pixels that changed are the tendon's. Where are they, and how did they change?
  long count = 0;
  double col_sum = 0, row_sum = 0, red_a = 0, red_b = 0, blue_a = 0, blue_b = 0;
  for (int row = 0; row < o.height; ++row) {
    for (int col = 0; col < o.width; ++col) {
      const size_t i = 3 * (static_cast<size_t>(row) * o.width + col);
      if (a[i] == b[i] && a[i + 1] == b[i + 1] && a[i + 2] == b[i + 2]) continue;
      ++count;
      col_sum += col;
      row_sum += o.height - 1 - row;  // GL rows are bottom-up
      red_a += a[i];
      red_b += b[i];
      blue_a += a[i + 2];
      blue_b += b[i + 2];
    }
  }
  ASSERT_GT(count, 300) << "the tendon should cover a few hundred pixels";
  EXPECT_GT(red_b / count, red_a / count + 80) << "hot tendon is redder";
  EXPECT_GT(blue_a / count, blue_b / count + 80) << "cold tendon is bluer";

  // The changed pixels' centroid lies on the projected tendon (a straight segment between its
  // two sites), near the projection of its midpoint.
  const int anchor = mj_name2id(m_.get(), mjOBJ_SITE, "anchor");
  const int insertion = mj_name2id(m_.get(), mjOBJ_SITE, "insertion");
  double mid[3];
  for (int k = 0; k < 3; ++k) {
    mid[k] = 0.5 * (d_->site_xpos[3 * anchor + k] + d_->site_xpos[3 * insertion + k]);
  }
  double col = 0, row = 0;
  testing::Project(m_.get(), d_.get(), mj_name2id(m_.get(), mjOBJ_CAMERA, "front"), mid, o.width,
                   o.height, &col, &row);
  EXPECT_NEAR(col_sum / count, col, 8.0);
  EXPECT_NEAR(row_sum / count, row, 8.0);
}

TEST_F(SceneRendererTest, MinimumTendonWidthThickensOnlyTheTendon) {
  RenderOptions o = Front();
  o.figures = false;
  o.text_panel = false;
  o.labels = false;
  o.heat_key = false;
  const TelemetrySample hot = Sample(1.0, 1.0);
  auto red_pixels = [&](const std::vector<unsigned char>& rgb) {
    long n = 0;
    for (size_t i = 0; i < rgb.size(); i += 3)
      n += rgb[i] > 120 && rgb[i + 1] < 90 && rgb[i + 2] < 90;
    return n;
  };
  const long thin = red_pixels(Render(o, &hot));  // model width 0.02 m (radius)
  o.min_tendon_width = 0.04;
  const long thick = red_pixels(Render(o, &hot));
  ASSERT_GT(thin, 300);
  // Reference: the drawn area of a capsule seen side on scales about with its radius.
  EXPECT_GT(thick, 1.6 * thin);
  EXPECT_LT(thick, 2.6 * thin);
}

TEST_F(SceneRendererTest, SameStateGivesIdenticalFrames) {
  const TelemetrySample s = Sample(2.0, 0.3);
  const std::vector<unsigned char> a = Render(Front(), &s);
  const std::vector<unsigned char> b = Render(Front(), &s);
  EXPECT_TRUE(a == b);
}

TEST_F(SceneRendererTest, FrameLargerThanTheModelsOffscreenBufferIsEnlarged) {
  // The model asks for a 640x480 offscreen buffer; 800x600 must still render fully.
  const TelemetrySample s = Sample(1.0, 1.0);
  RenderOptions o = Front(800, 600);
  const std::vector<unsigned char> rgb = Render(o, &s);
  ASSERT_EQ(rgb.size(), 800u * 600 * 3);
  // The strips outside the default 640x480 are drawn: the columns right of x = 640 hold the
  // plots, the rows above y = 480 the text panel.
  auto colours_in = [&](int col0, int col1, int row0, int row1) {
    std::set<int> colours;
    for (int row = row0; row < row1; ++row) {
      for (int col = col0; col < col1; ++col) {
        const size_t i = 3 * (static_cast<size_t>(row) * 800 + col);
        colours.insert(rgb[i] << 16 | rgb[i + 1] << 8 | rgb[i + 2]);
      }
    }
    return colours.size();
  };
  EXPECT_GT(colours_in(650, 800, 0, 600), 5u);
  long bright = 0;  // panel text (light grey and white) in the top strip
  for (int row = 490; row < 600; ++row) {
    for (int col = 0; col < 800; ++col) {
      const size_t i = 3 * (static_cast<size_t>(row) * 800 + col);
      bright += rgb[i] > 150 && rgb[i + 1] > 150 && rgb[i + 2] > 150;
    }
  }
  EXPECT_GT(bright, 200);
}

TEST_F(SceneRendererTest, UnknownCameraListsTheModelsCameras) {
  RenderOptions o;
  o.camera.name = "top";
  auto r = SceneRenderer::Create(m_.get(), o, RunLabel{});
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.error(), HasSubstr("'top'"));
  EXPECT_THAT(r.error(), HasSubstr("'front', 'side'"));
}

TEST_F(SceneRendererTest, CameraNameAndFreeParametersTogetherAreRejected) {
  RenderOptions o;
  o.camera.name = "front";
  o.camera.azimuth = 30;
  auto r = SceneRenderer::Create(m_.get(), o, RunLabel{});
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.error(), HasSubstr("not both"));
}

TEST_F(SceneRendererTest, FreeCameraParametersAreValidated) {
  RenderOptions o;
  o.camera.elevation = 120;
  auto r = SceneRenderer::Create(m_.get(), o, RunLabel{});
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.error(), HasSubstr("elevation must be in [-90, 90]"));
  o.camera.elevation.reset();
  o.camera.distance = -1;
  r = SceneRenderer::Create(m_.get(), o, RunLabel{});
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.error(), HasSubstr("distance must be a positive"));
}

TEST_F(SceneRendererTest, FreeCameraLooksWhereItIsTold) {
  // Looking at the tendon's midpoint from any angle puts it at the image centre.
  const int anchor = mj_name2id(m_.get(), mjOBJ_SITE, "anchor");
  const int insertion = mj_name2id(m_.get(), mjOBJ_SITE, "insertion");
  std::array<double, 3> mid;
  for (int k = 0; k < 3; ++k) {
    mid[k] = 0.5 * (d_->site_xpos[3 * anchor + k] + d_->site_xpos[3 * insertion + k]);
  }
  RenderOptions o;
  o.width = 320;
  o.height = 240;
  o.figures = false;
  o.text_panel = false;
  o.labels = false;
  o.heat_key = false;
  o.camera.azimuth = 70;
  o.camera.elevation = -15;
  o.camera.distance = 0.8;
  o.camera.lookat = mid;
  const TelemetrySample cold = Sample(0, 0), hot = Sample(0, 1);
  const auto a = Render(o, &cold), b = Render(o, &hot);
  // The changed (tendon) pixel closest to the centre is within a few pixels of it.
  double best = 1e9;
  for (int row = 0; row < o.height; ++row) {
    for (int col = 0; col < o.width; ++col) {
      const size_t i = 3 * (static_cast<size_t>(row) * o.width + col);
      if (a[i] != b[i] || a[i + 2] != b[i + 2]) {
        best = std::min(best, std::hypot(col - 0.5 * o.width, row - 0.5 * o.height));
      }
    }
  }
  EXPECT_LT(best, 4.0);
}

TEST_F(SceneRendererTest, InvalidSizesGiveClearErrors) {
  RenderOptions o;
  o.width = 10;
  EXPECT_THAT(o.Validate().error(), HasSubstr("width and height must be in [16, 8192]"));
  o.width = 640;
  o.height = 100000;
  auto r = SceneRenderer::Create(m_.get(), o, RunLabel{});
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.error(), HasSubstr("640x100000"));
}

TEST(HeatColourTest, BlueWhenColdRedWhenHotMonotoneBetween) {
  const auto cold = HeatColour(0), hot = HeatColour(1);
  EXPECT_GT(cold[2], 0.9f);
  EXPECT_LT(cold[0], 0.2f);
  EXPECT_GT(hot[0], 0.9f);
  EXPECT_LT(hot[2], 0.1f);
  for (int i = 1; i <= 10; ++i) {
    EXPECT_GT(HeatColour(i / 10.0)[0], HeatColour((i - 1) / 10.0)[0]);
    EXPECT_LT(HeatColour(i / 10.0)[2], HeatColour((i - 1) / 10.0)[2]);
  }
  EXPECT_EQ(HeatColour(2.0), hot);            // clamped
  EXPECT_EQ(HeatColour(std::nan("")), cold);  // NaN reads as cold
}

}  // namespace file_scene_renderer_test
}  // namespace recruit::render
