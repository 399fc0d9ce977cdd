// VideoRecorder end to end on the test arm: the MP4 is checked by ffprobe (an independent
// decoder), stills by lodepng, determinism by decoding two runs with ffmpeg's framemd5.
#include "render/video_recorder.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <lodepng.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "render/gif_writer.h"
#include "test_model.h"

namespace recruit::render {
namespace file_video_recorder_test {

namespace fs = std::filesystem;
using testing::DataPtr;
using ::testing::HasSubstr;
using testing::LoadXml;
using testing::ModelPtr;

std::string RunCommand(const std::string& cmd) {
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return out;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof(buf), p)) > 0) out.append(buf, n);
  pclose(p);
  return out;
}

// key=value lines from ffprobe -of default=noprint_wrappers=1.
std::map<std::string, std::string> Probe(const std::string& path) {
  const std::string out = RunCommand(
      "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
      "stream=codec_name,pix_fmt,width,height,nb_read_frames:format=duration,format_name "
      "-of default=noprint_wrappers=1 '" +
      path + "' 2>&1");
  std::map<std::string, std::string> kv;
  std::istringstream in(out);
  std::string line;
  while (std::getline(in, line)) {
    const auto eq = line.find('=');
    if (eq != std::string::npos) kv[line.substr(0, eq)] = line.substr(eq + 1);
  }
  return kv;
}

class VideoRecorderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    m_ = LoadXml(testing::kArmXml);
    ASSERT_NE(m_, nullptr);
    dir_ = fs::temp_directory_path() /
           ("recruit_render_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static VideoOptions Options(const std::string& mp4) {
    VideoOptions o;
    o.mp4_path = mp4;
    o.fps = 25;
    o.render.width = 320;
    o.render.height = 240;
    o.render.camera.name = "front";
    o.label = RunLabel{"test-arm", "kalman", 0.5, 0.2, 7};
    return o;
  }

  // Steps the arm for `seconds` with a pulling force that ramps up, feeding the recorder a
  // sample whose heat follows the force. Returns the first error.
  Status Drive(VideoRecorder* rec, double seconds, std::vector<double>* step_times = nullptr) {
    DataPtr d(mj_makeData(m_.get()));
    const int steps = static_cast<int>(std::lround(seconds / m_->opt.timestep));
    for (int i = 0; i < steps; ++i) {
      const double u = std::min(1.0, d->time / seconds);
      d->ctrl[0] = 15 * u;
      mj_step(m_.get(), d.get());
      if (step_times) step_times->push_back(d->time);
      const TelemetrySample s = testing::Sample(d->time, u, static_cast<int>(60 * u), 60 * u - 1);
      if (Status st = rec->OnStep(m_.get(), d.get(), s); !st.ok()) return st;
    }
    return rec->Finish();
  }

  std::vector<fs::path> Files() const {
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(dir_)) files.push_back(e.path().filename());
    std::sort(files.begin(), files.end());
    return files;
  }

  ModelPtr m_;
  fs::path dir_;
};

TEST_F(VideoRecorderTest, Mp4DecodesWithTheExpectedFramesSizeAndDuration) {
  const std::string path = (dir_ / "arm.mp4").string();
  auto rec = VideoRecorder::Create(Options(path));
  ASSERT_TRUE(rec.ok()) << rec.error();
  std::vector<double> times;
  Status s = Drive(rec->get(), 2.0, &times);
  ASSERT_TRUE(s.ok()) << s.error();

  // Reference frame count: frame k is due at k / fps, taken at the first step within half a
  // step of it; the last step is at t = 2 s, so k = 0..50.
  int expected = 0;
  while (expected / 25.0 <= times.back() + 0.5 * m_->opt.timestep) ++expected;
  EXPECT_EQ(expected, 51);
  EXPECT_EQ((*rec)->frames_rendered(), expected);

  const auto kv = Probe(path);
  EXPECT_EQ(kv.at("codec_name"), "h264");
  EXPECT_EQ(kv.at("pix_fmt"), "yuv420p");
  EXPECT_EQ(kv.at("width"), "320");
  EXPECT_EQ(kv.at("height"), "240");
  EXPECT_EQ(std::stoi(kv.at("nb_read_frames")), expected);
  EXPECT_NEAR(std::stod(kv.at("duration")), expected / 25.0, 0.05);
  EXPECT_THAT(kv.at("format_name"), HasSubstr("mp4"));

  // Faststart: the index (moov) comes before the media data (mdat), so browsers can stream it.
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_NE(bytes.find("moov"), std::string::npos);
  EXPECT_LT(bytes.find("moov"), bytes.find("mdat"));
  // Only the final file is left: the temporary was renamed.
  EXPECT_EQ(Files(), std::vector<fs::path>{"arm.mp4"});
}

TEST_F(VideoRecorderTest, GifAndStillsAreWrittenAndDecode) {
  VideoOptions o = Options((dir_ / "arm.mp4").string());
  o.gif_path = (dir_ / "arm.gif").string();
  o.gif_fps = 5;  // every 5th of 25 frames
  o.gif_width = 160;
  o.still_every = 1.0;
  o.still_times = {0.5};
  o.still_prefix = (dir_ / "still_").string();
  auto rec = VideoRecorder::Create(o);
  ASSERT_TRUE(rec.ok()) << rec.error();
  Status s = Drive(rec->get(), 2.0);
  ASSERT_TRUE(s.ok()) << s.error();

  const auto gif = Probe(o.gif_path);
  EXPECT_EQ(gif.at("codec_name"), "gif");
  EXPECT_EQ(gif.at("width"), "160");
  EXPECT_EQ(gif.at("height"), "120");
  EXPECT_EQ(std::stoi(gif.at("nb_read_frames")), 11);  // frames 0, 5, ..., 50

  // Stills at 0, 0.5, 1 and 2 s, each at the first frame at or after its time (frames are
  // 0.04 s apart: 0.5 s falls between the frames at 0.48 and 0.52 s).
  const std::vector<fs::path> expected = {"arm.gif",
                                          "arm.mp4",
                                          "still_t0000.002.png",
                                          "still_t0000.520.png",
                                          "still_t0001.000.png",
                                          "still_t0002.000.png"};
  EXPECT_EQ(Files(), expected);
  std::vector<unsigned char> image;
  unsigned w = 0, h = 0;
  ASSERT_EQ(lodepng::decode(image, w, h, (dir_ / "still_t0001.000.png").string(), LCT_RGB, 8), 0u);
  EXPECT_EQ(w, 320u);
  EXPECT_EQ(h, 240u);
  // Top-down order: the floor (light grey, lit from above) fills the bottom rows, the sky
  // (MuJoCo's dark default background) the top rows.
  auto brightness = [&](int row) {
    double sum = 0;
    for (int col = 0; col < 100; ++col) {
      const size_t i = 3 * (static_cast<size_t>(row) * w + col);
      sum += image[i] + image[i + 1] + image[i + 2];
    }
    return sum / 300;
  };
  EXPECT_GT(brightness(235), brightness(120) + 30);
}

TEST_F(VideoRecorderTest, SameInputsGiveIdenticalDecodedFrames) {
  std::vector<std::string> md5;
  for (const char* name : {"a.mp4", "b.mp4"}) {
    auto rec = VideoRecorder::Create(Options((dir_ / name).string()));
    ASSERT_TRUE(rec.ok()) << rec.error();
    ASSERT_TRUE(Drive(rec->get(), 1.0).ok());
    // framemd5: one hash per decoded frame, from ffmpeg's own decoder. Only its rows ("stream,
    // dts, pts, duration, size, hash"): a clean-clone run once had ffmpeg's debug log in the
    // same stream around identical rows.
    std::string out = RunCommand("ffmpeg -v error -i '" + (dir_ / name).string() +
                                 "' -f framemd5 - 2>&1 | grep -E '^[0-9]+, '");
    ASSERT_FALSE(out.empty());
    md5.push_back(out);
  }
  EXPECT_EQ(md5[0], md5[1]);
  EXPECT_GT(std::count(md5[0].begin(), md5[0].end(), '\n'), 20);
}

TEST_F(VideoRecorderTest, FramesDifferAsTheArmMoves) {
  auto rec = VideoRecorder::Create(Options((dir_ / "arm.mp4").string()));
  ASSERT_TRUE(rec.ok());
  std::vector<std::vector<unsigned char>> frames;
  (*rec)->set_frame_tap([&](const Frame& f) { frames.push_back(f.rgb); });
  ASSERT_TRUE(Drive(rec->get(), 1.0).ok());
  ASSERT_EQ(frames.size(), 26u);
  EXPECT_NE(frames.front(), frames.back());
}

TEST_F(VideoRecorderTest, UnwritablePathFailsBeforeTheRun) {
  auto rec = VideoRecorder::Create(Options("/nonexistent-dir/x.mp4"));
  ASSERT_FALSE(rec.ok());
  EXPECT_THAT(rec.error(), HasSubstr("/nonexistent-dir/x.mp4"));
}

TEST_F(VideoRecorderTest, BadOptionsGiveClearErrors) {
  VideoOptions o = Options((dir_ / "x.avi").string());
  EXPECT_THAT(VideoRecorder::Create(o).error(), HasSubstr("must end in .mp4"));
  o = Options((dir_ / "x.mp4").string());
  o.render.width = 321;
  EXPECT_THAT(VideoRecorder::Create(o).error(), HasSubstr("even width and height"));
  o = Options((dir_ / "x.mp4").string());
  o.fps = 0;
  EXPECT_THAT(VideoRecorder::Create(o).error(), HasSubstr("fps must be in [1, 240]"));
  o = Options((dir_ / "x.mp4").string());
  o.h264.preset = "warp";
  EXPECT_THAT(VideoRecorder::Create(o).error(), HasSubstr("preset 'warp' is unknown"));
  o = Options((dir_ / "x.mp4").string());
  o.gif_path = (dir_ / "x.gif").string();
  o.gif_fps = 50;
  EXPECT_THAT(VideoRecorder::Create(o).error(), HasSubstr("GIF frame rate must be in [1, fps"));
  EXPECT_TRUE(Files().empty()) << "no output may be left behind";
}

TEST_F(VideoRecorderTest, UnknownCameraStopsTheRunAndLeavesNoFile) {
  VideoOptions o = Options((dir_ / "arm.mp4").string());
  o.render.camera.name = "overhead";
  auto rec = VideoRecorder::Create(o);
  ASSERT_TRUE(rec.ok());
  Status s = Drive(rec->get(), 0.1);
  ASSERT_FALSE(s.ok());
  EXPECT_THAT(s.error(), HasSubstr("no camera named 'overhead'"));
  EXPECT_THAT(s.error(), HasSubstr("'front', 'side'"));
  rec->reset();
  EXPECT_TRUE(Files().empty());
}

TEST_F(VideoRecorderTest, AbandonedRunLeavesNoFile) {
  auto rec = VideoRecorder::Create(Options((dir_ / "arm.mp4").string()));
  ASSERT_TRUE(rec.ok());
  DataPtr d(mj_makeData(m_.get()));
  for (int i = 0; i < 100; ++i) {
    mj_step(m_.get(), d.get());
    ASSERT_TRUE((*rec)->OnStep(m_.get(), d.get(), testing::Sample(d->time, 0)).ok());
  }
  rec->reset();  // destroyed without Finish(), as when the run fails
  EXPECT_TRUE(Files().empty());
}

TEST(PaletteTest, ReservedAndDominantColoursMapExactly) {
  // Four flat colours (multiples of 8 plus 4, the RGB555 bin centres) map to themselves.
  std::vector<unsigned char> rgb;
  const unsigned char colours[4][3] = {{12, 20, 28}, {100, 4, 4}, {4, 180, 4}, {244, 244, 244}};
  for (int i = 0; i < 400; ++i) rgb.insert(rgb.end(), colours[i % 4], colours[i % 4] + 3);
  const Palette p = Palette::FromImage(rgb.data(), 400, {{255, 0, 0}});
  ASSERT_EQ(p.colours().size(), 256u);
  EXPECT_EQ(p.colours()[p.Index(255, 0, 0)], (std::array<uint8_t, 3>{255, 0, 0}));
  for (const auto& c : colours) {
    const auto& got = p.colours()[p.Index(c[0], c[1], c[2])];
    EXPECT_EQ(got, (std::array<uint8_t, 3>{c[0], c[1], c[2]}));
  }
}

}  // namespace file_video_recorder_test
}  // namespace recruit::render
