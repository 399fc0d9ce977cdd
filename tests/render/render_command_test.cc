// `recruit render` end to end on a short isometric-bench task: the video decodes with the
// expected frame count (ffprobe), the same seed gives identical decoded frames and another seed
// does not (ffmpeg framemd5), and bad options fail with the documented exit code (2 usage, 3 input,
// 4 I/O), a clear message and no file.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>

namespace recruit::render {
namespace file_render_command_test {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

struct Output {
  int exit_code = -1;
  std::string text;  // stdout and stderr
};

Output Shell(const std::string& cmd) {
  Output out;
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return out;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof(buf), p)) > 0) out.text.append(buf, n);
  const int status = pclose(p);
  out.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return out;
}

class RenderCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("recruit_render_cli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  Output Render(const std::string& args) {
    return Shell(std::string(RECRUIT_BIN) + " render --task " + RECRUIT_SOURCE_DIR +
                 "/tests/render/data/bench_task.json " + args);
  }
  std::string FrameMd5(const std::string& path) {
    return Shell("ffmpeg -v error -i '" + path + "' -f framemd5 - | grep -v '^#'").text;
  }
  bool Empty() const { return fs::is_empty(dir_); }

  fs::path dir_;
};

TEST_F(RenderCommandTest, SameSeedSameFramesOtherSeedOtherFrames) {
  const std::string a = (dir_ / "a.mp4").string(), b = (dir_ / "b.mp4").string(),
                    c = (dir_ / "c.mp4").string();
  const std::string size = " --width 320 --height 240 --seed ";
  Output ra = Render("--out " + a + size + "5 --stills 1");
  ASSERT_EQ(ra.exit_code, 0) << ra.text;
  ASSERT_EQ(Render("--out " + b + size + "5").exit_code, 0);
  ASSERT_EQ(Render("--out " + c + size + "6").exit_code, 0);

  // 1.5 s at 30 frames/s: frames at 0, 1/30, ..., 1.5 s.
  const Output probe = Shell(
      "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
      "stream=nb_read_frames,width,height -of csv=p=0 '" +
      a + "'");
  EXPECT_EQ(probe.text, "320,240,46\n");
  EXPECT_TRUE(fs::exists(dir_ / "a_t0001.000.png")) << ra.text;

  const std::string ma = FrameMd5(a), mb = FrameMd5(b), mc = FrameMd5(c);
  ASSERT_FALSE(ma.empty());
  EXPECT_EQ(ma, mb) << "same seed, same frames";
  EXPECT_NE(ma, mc) << "another seed draws other units: the panel and plots differ";
}

TEST_F(RenderCommandTest, UnknownCameraIsNamedWithTheModelsCameras) {
  Output r = Render("--out " + (dir_ / "x.mp4").string() + " --camera nope");
  EXPECT_EQ(r.exit_code, 2);  // a bad option value: usage (docs/reliability.md)
  EXPECT_THAT(r.text, HasSubstr("no camera named 'nope'"));
  EXPECT_THAT(r.text, HasSubstr("isometric_bench.xml"));
  EXPECT_THAT(r.text, HasSubstr("defines no cameras"));
  EXPECT_TRUE(Empty());
}

TEST_F(RenderCommandTest, BadSizesAreRefusedWithTheAllowedRange) {
  Output odd = Render("--out " + (dir_ / "x.mp4").string() + " --width 641");
  EXPECT_EQ(odd.exit_code, 2);  // docs/reliability.md
  EXPECT_THAT(odd.text, HasSubstr("641x480"));
  EXPECT_THAT(odd.text, HasSubstr("even width and height"));
  Output huge = Render("--out " + (dir_ / "x.mp4").string() + " --height 20000");
  EXPECT_EQ(huge.exit_code, 2);  // docs/reliability.md
  EXPECT_THAT(huge.text, HasSubstr("[16, 8192]"));
  // Within the side limit but beyond H.264's largest frame (level 6.2: 139264 macroblocks):
  // refused before any rendering or allocation.
  Output square = Render("--out " + (dir_ / "x.mp4").string() + " --width 8192 --height 8192");
  EXPECT_EQ(square.exit_code, 2);
  EXPECT_THAT(square.text, HasSubstr("262144 macroblocks"));
  EXPECT_THAT(square.text, HasSubstr("139264"));
  EXPECT_TRUE(Empty());
}

TEST_F(RenderCommandTest, StillsAfterTheEndAndBadDurationsAreUsageErrors) {
  Output late = Render("--out " + (dir_ / "x.mp4").string() + " --duration 0.5 --stills 0.2,3");
  EXPECT_EQ(late.exit_code, 2);
  EXPECT_THAT(late.text, HasSubstr("--stills: 3 s is after the run's end (0.5 s)"));
  for (const char* d : {"-1", "0", "1e400", "nan", "abc"}) {
    Output bad = Render("--out " + (dir_ / "x.mp4").string() + " --duration " + d);
    EXPECT_EQ(bad.exit_code, 2) << d;
    EXPECT_THAT(bad.text, HasSubstr("--duration")) << d;
    EXPECT_THAT(bad.text, ::testing::Not(HasSubstr("1.79769e+308"))) << d;
    EXPECT_THAT(bad.text, ::testing::Not(HasSubstr("DBL_MAX"))) << d;
  }
  EXPECT_TRUE(Empty());
}

TEST_F(RenderCommandTest, UnwritableOutputIsNamed) {
  Output r = Render("--out /nonexistent-dir/x.mp4");
  EXPECT_EQ(r.exit_code, 4);  // docs/reliability.md
  EXPECT_THAT(r.text, HasSubstr("cannot write '/nonexistent-dir/x.mp4'"));
  Output ext = Render("--out " + (dir_ / "x.avi").string());
  EXPECT_EQ(ext.exit_code, 2);  // docs/reliability.md
  EXPECT_THAT(ext.text, HasSubstr("must end in .mp4"));
  EXPECT_TRUE(Empty());
}

TEST_F(RenderCommandTest, CameraAndFreeCameraOptionsExcludeEachOther) {
  Output r = Render("--out " + (dir_ / "x.mp4").string() + " --camera a --azimuth 3");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.text, HasSubstr("excludes"));
}

}  // namespace file_render_command_test
}  // namespace recruit::render
