#include "render/video_recorder.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace recruit::render {
namespace {

bool EndsWith(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  for (size_t i = 0; i < suffix.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(s[s.size() - suffix.size() + i])) != suffix[i]) {
      return false;
    }
  }
  return true;
}

int GifStride(const VideoOptions& o) {
  return std::max(1, static_cast<int>(std::lround(static_cast<double>(o.fps) / o.gif_fps)));
}

}  // namespace

Status VideoOptions::Validate() const {
  if (Status s = render.Validate(); !s.ok()) return s;
  const bool stills = still_every > 0 || !still_times.empty();
  if (mp4_path.empty() && gif_path.empty() && !stills) {
    return Error{"nothing to write: give an MP4 path, a GIF path or stills"};
  }
  if (fps < 1 || fps > 240) {
    return Error{"fps must be in [1, 240] frames/s, got " + std::to_string(fps)};
  }
  if (!mp4_path.empty()) {
    if (!EndsWith(mp4_path, ".mp4")) {
      return Error{"video output '" + mp4_path + "' must end in .mp4 (H.264 in MP4)"};
    }
    if (render.width % 2 || render.height % 2) {
      return Error{"frame size " + std::to_string(render.width) + "x" +
                   std::to_string(render.height) +
                   ": H.264 in yuv420p (what browsers play) needs an even width and height"};
    }
    // H.264's largest level (6.2) allows 139264 macroblocks of 16 x 16 pixels per frame: e.g.
    // 8192 x 4352, 7680 x 4320 (8K UHD); 8192 x 8192 is twice that.
    const long mbs = static_cast<long>((render.width + 15) / 16) * ((render.height + 15) / 16);
    if (mbs > kMaxH264Macroblocks) {
      return Error{"frame size " + std::to_string(render.width) + "x" +
                   std::to_string(render.height) + " is " + std::to_string(mbs) +
                   " macroblocks of 16x16 px; H.264 (level 6.2, its largest) allows at most " +
                   std::to_string(kMaxH264Macroblocks) +
                   " per frame (e.g. 7680x4320 or 8192x4352)"};
    }
    if (Status s = h264.Validate(); !s.ok()) return s;
  }
  if (!gif_path.empty()) {
    if (!EndsWith(gif_path, ".gif")) return Error{"GIF output '" + gif_path + "' must end in .gif"};
    if (gif_fps < 1 || gif_fps > fps) {
      return Error{"GIF frame rate must be in [1, fps = " + std::to_string(fps) + "], got " +
                   std::to_string(gif_fps)};
    }
    if (gif_width < 16 || gif_width > render.width) {
      return Error{"GIF width must be in [16, " + std::to_string(render.width) +
                   "] (the frame width), got " + std::to_string(gif_width)};
    }
  }
  if (!std::isfinite(still_every) || still_every < 0) {
    return Error{"still interval must be >= 0 s (0 = no periodic stills)"};
  }
  for (double t : still_times) {
    if (!std::isfinite(t) || t < 0) {
      return Error{"still times must be finite and >= 0 s, got " + std::to_string(t)};
    }
  }
  if (stills && still_prefix.empty()) return Error{"stills requested but no still prefix given"};
  if (queue_frames < 0 || queue_frames > 64) {
    return Error{"encoder queue must hold 0 to 64 frames, got " + std::to_string(queue_frames)};
  }
  return Status::Ok();
}

Result<std::unique_ptr<VideoRecorder>> VideoRecorder::Create(const VideoOptions& options) {
  if (Status s = options.Validate(); !s.ok()) return Error{s.error(), s.code()};
  std::unique_ptr<VideoRecorder> r(new VideoRecorder(options));
  const int w = options.render.width, h = options.render.height;
  std::unique_ptr<Mp4Writer> mp4;
  if (!options.mp4_path.empty()) {
    auto opened = Mp4Writer::Open(options.mp4_path, w, h, options.fps, options.h264);
    if (!opened.ok()) return Error{opened.error(), opened.code()};
    mp4 = std::move(*opened);
  }
  std::unique_ptr<GifWriter> gif;
  if (!options.gif_path.empty()) {
    const int stride = GifStride(options);
    auto opened = GifWriter::Open(options.gif_path, w, h, options.gif_width,
                                  static_cast<double>(stride) / options.fps);
    if (!opened.ok()) return Error{opened.error(), opened.code()};
    gif = std::move(*opened);
  }
  r->pipeline_ = std::make_unique<EncodePipeline>(w, h, std::move(mp4), std::move(gif),
                                                  GifStride(options), options.queue_frames);
  r->pending_stills_ = options.still_times;
  std::sort(r->pending_stills_.begin(), r->pending_stills_.end());
  return r;
}

Status VideoRecorder::Prepare(const mjModel* m) {
  if (renderer_) return Status::Ok();
  auto renderer = SceneRenderer::Create(m, options_.render, options_.label);
  if (!renderer.ok()) return Error{renderer.error(), renderer.code()};
  renderer_ = std::move(*renderer);
  return Status::Ok();
}

std::string VideoRecorder::StillPathFor(double frame_time, double tolerance) {
  // A still is due at the first frame at or after its requested time (to within `tolerance`,
  // half a physics step, so that t = 1 s is not missed by rounding).
  bool due = false;
  while (!pending_stills_.empty() && pending_stills_.front() <= frame_time + tolerance) {
    pending_stills_.erase(pending_stills_.begin());
    due = true;
  }
  if (options_.still_every > 0) {
    while (next_periodic_still_ <= frame_time + tolerance) {
      next_periodic_still_ += options_.still_every;
      due = true;
    }
  }
  if (!due) return "";
  char buf[32];
  std::snprintf(buf, sizeof(buf), "t%08.3f.png", frame_time);
  return options_.still_prefix + buf;
}

Status VideoRecorder::OnStep(const mjModel* m, const mjData* d, const TelemetrySample& sample) {
  if (finished_) return Error{"video recorder: OnStep after Finish"};
  const double slack = 0.5 * m->opt.timestep;
  if (d->time + slack < static_cast<double>(next_index_) / options_.fps) return Status::Ok();
  if (Status s = Prepare(m); !s.ok()) return s;

  auto frame = pipeline_->Acquire();
  if (!frame.ok()) return Error{frame.error(), frame.code()};
  renderer_->AddPlotPoint(m, d, sample);
  if (Status s = renderer_->Render(m, d, &sample, (*frame)->rgb.data()); !s.ok()) {
    (void)pipeline_->Submit(*frame);  // hand the buffer back; the error stops the run
    return s;
  }
  ++renders_;
  Frame* first = *frame;
  first->index = next_index_++;
  first->time = d->time;
  last_frame_time_ = d->time;
  first->still_path = StillPathFor(d->time, slack);
  if (tap_) tap_(*first);
  // Physics steps longer than a frame period: repeat the image for every frame now due.
  std::vector<unsigned char> copy;
  const bool repeat = static_cast<double>(next_index_) / options_.fps <= d->time + slack;
  if (repeat) copy = first->rgb;
  if (Status s = pipeline_->Submit(first); !s.ok()) return s;
  while (static_cast<double>(next_index_) / options_.fps <= d->time + slack) {
    auto dup = pipeline_->Acquire();
    if (!dup.ok()) return Error{dup.error(), dup.code()};
    std::memcpy((*dup)->rgb.data(), copy.data(), copy.size());
    (*dup)->index = next_index_++;
    (*dup)->time = d->time;
    if (tap_) tap_(**dup);
    if (Status s = pipeline_->Submit(*dup); !s.ok()) return s;
  }
  return Status::Ok();
}

Status VideoRecorder::Finish() {
  if (finished_) return Status::Ok();
  finished_ = true;
  if (next_index_ == 0) return Error{"video recorder: the run ended before the first frame"};
  if (Status s = pipeline_->Finish(); !s.ok()) return s;
  // A still due after the last frame cannot be taken: say so rather than drop it.
  if (!pending_stills_.empty()) {
    char msg[200];
    std::snprintf(msg, sizeof(msg),
                  "%zu still(s) not written: requested at %g s and later, after the last frame "
                  "(t = %g s); the video and the other stills were written",
                  pending_stills_.size(), pending_stills_.front(), last_frame_time_);
    return Error{msg};
  }
  return Status::Ok();
}

std::vector<std::string> VideoRecorder::stills_written() const {
  return pipeline_->stills_written();
}

}  // namespace recruit::render
