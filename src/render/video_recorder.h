// VideoRecorder: a StepObserver that films a task while it runs (no second simulation). On each
// physics step where a frame is due (frame k shows the first step with time >= k / fps, to
// within half a step) it renders the scene with SceneRenderer and hands the frame to an
// EncodePipeline: H.264 MP4, optionally a GIF and PNG stills. Outputs are written through
// temporary files and renamed into place by Finish(); a run that stops early leaves none.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "common/step_observer.h"
#include "render/encode_pipeline.h"
#include "render/mp4_writer.h"
#include "render/scene_renderer.h"

namespace recruit::render {

// H.264 level 6.2's MaxFS: the most 16 x 16 macroblocks a frame may have.
inline constexpr long kMaxH264Macroblocks = 139264;

struct VideoOptions {
  std::string mp4_path;             // H.264 MP4 (".mp4"); empty = none
  std::string gif_path;             // animated GIF (".gif"); empty = none
  int fps = 30;                     // video frame rate, frames/s, in [1, 240]
  int gif_fps = 10;                 // GIF frame rate; every round(fps / gif_fps)-th frame, <= fps
  int gif_width = 320;              // GIF width in pixels (height keeps the aspect ratio)
  double still_every = 0;           // s between PNG stills; 0 = none
  std::vector<double> still_times;  // s, extra PNG stills at these times
  std::string still_prefix;         // stills are "<prefix>t<frame time, %08.3f>.png"
  H264Options h264;
  int queue_frames = 4;  // frames buffered for the encoder thread; 0 = encode inline
  RenderOptions render;
  RunLabel label;

  // Checks everything that needs no model: sizes, rates, names, at least one output.
  Status Validate() const;
};

class VideoRecorder final : public StepObserver {
 public:
  // Validates the options and opens the output files (as temporaries): a bad path fails here,
  // before the run starts.
  static Result<std::unique_ptr<VideoRecorder>> Create(const VideoOptions& options);

  // Builds the renderer for this model now (camera and size checks, GL context); otherwise the
  // first OnStep does it. Must run on the thread that will call OnStep.
  Status Prepare(const mjModel* m);

  Status OnStep(const mjModel* m, const mjData* d, const TelemetrySample& sample) override;
  // Closes the outputs. A still requested after the last frame is an error (the outputs that
  // were made are kept); `recruit render` refuses such times before the run.
  Status Finish() override;

  int64_t frames_rendered() const { return next_index_; }
  int64_t renders() const { return renders_; }  // scene renders (duplicated frames render once)
  std::vector<std::string> stills_written() const;
  const SceneRenderer* renderer() const { return renderer_.get(); }

  // Test and tooling hook: sees every rendered frame on the render thread, before encoding.
  void set_frame_tap(std::function<void(const Frame&)> tap) { tap_ = std::move(tap); }

 private:
  explicit VideoRecorder(const VideoOptions& options) : options_(options) {}
  std::string StillPathFor(double frame_time, double tolerance);

  VideoOptions options_;
  std::unique_ptr<SceneRenderer> renderer_;
  std::unique_ptr<EncodePipeline> pipeline_;
  std::vector<double> pending_stills_;  // sorted, consumed from the front
  double next_periodic_still_ = 0;
  int64_t next_index_ = 0;
  double last_frame_time_ = 0;
  int64_t renders_ = 0;
  bool finished_ = false;
  std::function<void(const Frame&)> tap_;
};

}  // namespace recruit::render
