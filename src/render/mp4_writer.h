// Mp4Writer: H.264 (libx264 through libavcodec) in MP4, yuv420p with BT.709 tags and the moov
// atom at the front (faststart), so the file plays in a browser while it downloads.
#pragma once

#include <memory>
#include <string>

#include "common/result.h"
#include "render/frame.h"
#include "render/libav_output.h"

struct AVCodecContext;
struct AVFrame;
struct SwsContext;

namespace recruit::render {

struct H264Options {
  // x264 preset. "veryfast" by default: about 2-3 ms of CPU per 640x480 frame against ~30 ms to
  // render it, and files 2.5 times smaller than "ultrafast" (docs/benchmarks.md).
  std::string preset = "veryfast";
  int crf = 23;  // constant rate factor, 0 (lossless) .. 51; 23 is x264's default
  // x264 threads. A fixed count by default: x264's decoded frames depend on its thread count,
  // and 0 (libavcodec's choice, 1.5 per core) would make the same run's video differ from one
  // machine to the next.
  int threads = 4;

  Status Validate() const;
};

class Mp4Writer {
 public:
  // width and height must be even (yuv420p halves the chroma planes); fps in [1, 240].
  static Result<std::unique_ptr<Mp4Writer>> Open(const std::string& path, int width, int height,
                                                 int fps, const H264Options& options);
  ~Mp4Writer();
  Mp4Writer(const Mp4Writer&) = delete;
  Mp4Writer& operator=(const Mp4Writer&) = delete;

  // Encodes one frame (bottom-up RGB) at pts = frame.index.
  Status Write(const Frame& frame);
  // Flushes the encoder, writes the index at the front, renames the file into place.
  Status Finish();
  const std::string& path() const { return output_->path(); }

 private:
  Mp4Writer() = default;

  std::unique_ptr<LibavOutput> output_;
  AVCodecContext* codec_ = nullptr;
  AVFrame* yuv_ = nullptr;
  SwsContext* sws_ = nullptr;
  int width_ = 0, height_ = 0;
};

}  // namespace recruit::render
