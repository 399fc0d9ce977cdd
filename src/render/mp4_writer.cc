#include "render/mp4_writer.h"

#include <array>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

namespace recruit::render {
namespace {

constexpr std::array<const char*, 10> kPresets = {"ultrafast", "superfast", "veryfast", "faster",
                                                  "fast",      "medium",    "slow",     "slower",
                                                  "veryslow",  "placebo"};

std::string PresetList() {
  std::string s;
  for (const char* p : kPresets) s += std::string(s.empty() ? "" : ", ") + p;
  return s;
}

}  // namespace

Status H264Options::Validate() const {
  bool known = false;
  for (const char* p : kPresets) known = known || preset == p;
  if (!known) return Error{"x264 preset '" + preset + "' is unknown; allowed: " + PresetList()};
  if (crf < 0 || crf > 51) return Error{"x264 crf must be in [0, 51], got " + std::to_string(crf)};
  if (threads < 0 || threads > 64) {
    return Error{"encoder threads must be in [0, 64] (0 = one and a half per core), got " +
                 std::to_string(threads)};
  }
  return Status::Ok();
}

Mp4Writer::~Mp4Writer() {
  sws_freeContext(sws_);
  av_frame_free(&yuv_);
  avcodec_free_context(&codec_);
  // output_ removes its temporary file unless Finish() committed it.
}

Result<std::unique_ptr<Mp4Writer>> Mp4Writer::Open(const std::string& path, int width, int height,
                                                   int fps, const H264Options& options) {
  if (Status s = options.Validate(); !s.ok()) return Error{s.error(), s.code()};
  if (width <= 0 || height <= 0 || width % 2 || height % 2) {
    return Error{"video size " + std::to_string(width) + "x" + std::to_string(height) +
                 ": H.264 in yuv420p needs an even width and height"};
  }
  if (fps < 1 || fps > 240) {
    return Error{"video frame rate must be in [1, 240] frames/s, got " + std::to_string(fps)};
  }
  const AVCodec* codec = avcodec_find_encoder_by_name("libx264");
  if (!codec) return Error{"this libavcodec was built without libx264 (H.264 encoder)"};

  std::unique_ptr<Mp4Writer> w(new Mp4Writer());
  w->width_ = width;
  w->height_ = height;
  auto output = LibavOutput::Open(path, "mp4");
  if (!output.ok()) return Error{output.error(), output.code()};
  w->output_ = std::move(*output);

  w->codec_ = avcodec_alloc_context3(codec);
  if (!w->codec_) return Error{"out of memory"};
  AVCodecContext* c = w->codec_;
  c->width = width;
  c->height = height;
  c->time_base = AVRational{1, fps};
  c->framerate = AVRational{fps, 1};
  c->pix_fmt = AV_PIX_FMT_YUV420P;
  c->gop_size = 2 * fps;  // a keyframe every 2 s keeps seeking quick
  c->thread_count = options.threads;
  c->color_range = AVCOL_RANGE_MPEG;
  c->colorspace = AVCOL_SPC_BT709;
  c->color_primaries = AVCOL_PRI_BT709;
  c->color_trc = AVCOL_TRC_BT709;
  if (w->output_->wants_global_header()) c->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  av_opt_set(c->priv_data, "preset", options.preset.c_str(), 0);
  av_opt_set_int(c->priv_data, "crf", options.crf, 0);
  int err = avcodec_open2(c, codec, nullptr);
  if (err < 0) return Error{"cannot open the H.264 encoder: " + AvError(err), ErrorCode::kIo};
  if (Status s = w->output_->AddStream(c); !s.ok()) return Error{s.error(), s.code()};
  AVDictionary* mux_options = nullptr;
  av_dict_set(&mux_options, "movflags", "+faststart", 0);
  Status header = w->output_->WriteHeader(&mux_options);
  av_dict_free(&mux_options);
  if (!header.ok()) return Error{header.error(), header.code()};

  w->yuv_ = av_frame_alloc();
  if (!w->yuv_) return Error{"out of memory"};
  w->yuv_->format = AV_PIX_FMT_YUV420P;
  w->yuv_->width = width;
  w->yuv_->height = height;
  err = av_frame_get_buffer(w->yuv_, 0);
  if (err < 0) return Error{"cannot allocate a video frame: " + AvError(err), AvCode(err)};
  w->sws_ = sws_getContext(width, height, AV_PIX_FMT_RGB24, width, height, AV_PIX_FMT_YUV420P,
                           SWS_BILINEAR, nullptr, nullptr, nullptr);
  if (!w->sws_) return Error{"cannot create the RGB to YUV converter", ErrorCode::kIo};
  // Full-range RGB in, limited-range BT.709 YUV out, matching the stream's tags.
  sws_setColorspaceDetails(w->sws_, sws_getCoefficients(SWS_CS_ITU709), 1,
                           sws_getCoefficients(SWS_CS_ITU709), 0, 0, 1 << 16, 1 << 16);
  return w;
}

Status Mp4Writer::Write(const Frame& frame) {
  if (frame.width != width_ || frame.height != height_) {
    return Error{"'" + path() + "': frame size changed during the video"};
  }
  const int err = av_frame_make_writable(yuv_);
  if (err < 0) return Error{"'" + path() + "': " + AvError(err), AvCode(err)};
  // Negative stride from the top row: the bottom-up GL rows come out top-down, no copy.
  const uint8_t* src[1] = {frame.TopRow()};
  const int stride[1] = {-3 * width_};
  sws_scale(sws_, src, stride, 0, height_, yuv_->data, yuv_->linesize);
  yuv_->pts = frame.index;
  return output_->Encode(yuv_);
}

Status Mp4Writer::Finish() { return output_->Finish(); }

}  // namespace recruit::render
