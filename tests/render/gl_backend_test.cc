// GL back-end selection. MuJoCo binds its GL loader once per process, so the EGL check runs in a
// fresh process (this binary re-run on the disabled child test); it is skipped where EGL cannot
// create a context (no GPU driver and no Mesa software EGL device).
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <set>
#include <vector>

#include "render/gl_context.h"
#include "render/scene_renderer.h"
#include "test_model.h"

namespace recruit::render {
namespace file_gl_backend_test {

using ::testing::HasSubstr;

TEST(GlBackendTest, ParsesNamesAndRejectsOthersWithTheAllowedList) {
  EXPECT_EQ(*ParseGlBackend("osmesa"), GlBackend::kOsMesa);
  EXPECT_EQ(*ParseGlBackend("egl"), GlBackend::kEgl);
  auto bad = ParseGlBackend("glx");
  ASSERT_FALSE(bad.ok());
  EXPECT_THAT(bad.error(), HasSubstr("'osmesa'"));
  EXPECT_THAT(bad.error(), HasSubstr("'egl'"));
}

TEST(GlBackendTest, DISABLED_EglChild) {
  auto ctx = GlContext::Create(GlBackend::kEgl, 64, 64);
  if (!ctx.ok()) GTEST_SKIP() << "EGL not usable here: " << ctx.error();
  ctx->reset();
  auto m = testing::LoadXml(testing::kArmXml);
  ASSERT_NE(m, nullptr);
  testing::DataPtr d(mj_makeData(m.get()));
  mj_forward(m.get(), d.get());
  RenderOptions o;
  o.backend = GlBackend::kEgl;
  o.camera.name = "front";
  auto r = SceneRenderer::Create(m.get(), o, RunLabel{});
  ASSERT_TRUE(r.ok()) << r.error();
  std::cout << "EGL renderer: " << (*r)->gl_description() << "\n";
  std::vector<unsigned char> rgb(640 * 480 * 3);
  const TelemetrySample s = testing::Sample(1, 1);
  ASSERT_TRUE((*r)->Render(m.get(), d.get(), &s, rgb.data()).ok());
  std::set<int> colours;
  for (size_t i = 0; i < rgb.size(); i += 3)
    colours.insert(rgb[i] << 16 | rgb[i + 1] << 8 | rgb[i + 2]);
  EXPECT_GT(colours.size(), 200u);
  // A second back end in the same process is refused with an explanation.
  auto other = GlContext::Create(GlBackend::kOsMesa, 64, 64);
  ASSERT_FALSE(other.ok());
  EXPECT_THAT(other.error(), HasSubstr("once per process"));
}

TEST(GlBackendTest, EglRendersANonBlankFrameWhenAvailable) {
  char exe[4096] = {0};
  ASSERT_GT(readlink("/proc/self/exe", exe, sizeof(exe) - 1), 0);
  const std::string cmd = std::string("'") + exe +
                          "' --gtest_also_run_disabled_tests "
                          "--gtest_filter=GlBackendTest.DISABLED_EglChild 2>&1";
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof(buf), p)) > 0) out.append(buf, n);
  const int status = pclose(p);
  if (out.find("[  SKIPPED ]") != std::string::npos) GTEST_SKIP() << out;
  EXPECT_EQ(status, 0) << out;
  EXPECT_THAT(out, HasSubstr("[  PASSED  ] 1 test"));
  std::cout << out.substr(0, out.find('\n', out.find("EGL renderer")) + 1);
}

}  // namespace file_gl_backend_test
}  // namespace recruit::render
