#include "render/gif_writer.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "render/tendon_heat.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libswscale/swscale.h>
}

namespace recruit::render {
namespace {

struct Box {
  std::vector<uint16_t> colours;  // RGB555 keys with non-zero counts
  int64_t weight = 0;
};

int Channel(uint16_t key, int c) { return (key >> (10 - 5 * c)) & 31; }

}  // namespace

Palette Palette::FromImage(const unsigned char* rgb, size_t pixels,
                           const std::vector<std::array<uint8_t, 3>>& reserved) {
  std::vector<int64_t> hist(32768, 0);
  for (size_t i = 0; i < pixels; ++i) {
    const unsigned char* p = rgb + 3 * i;
    ++hist[((p[0] >> 3) << 10) | ((p[1] >> 3) << 5) | (p[2] >> 3)];
  }
  Palette pal;
  pal.colours_ = reserved;
  const int budget = 256 - static_cast<int>(reserved.size());
  std::vector<Box> boxes(1);
  for (int key = 0; key < 32768; ++key) {
    if (hist[key]) {
      boxes[0].colours.push_back(static_cast<uint16_t>(key));
      boxes[0].weight += hist[key];
    }
  }
  // Median cut: split the heaviest splittable box along its widest channel at the weighted
  // median, until the budget is used.
  while (static_cast<int>(boxes.size()) < budget) {
    int best = -1;
    int64_t best_weight = 0;
    for (size_t b = 0; b < boxes.size(); ++b) {
      if (boxes[b].colours.size() > 1 && boxes[b].weight > best_weight) {
        best = static_cast<int>(b);
        best_weight = boxes[b].weight;
      }
    }
    if (best < 0) break;
    Box& box = boxes[best];
    int lo[3] = {31, 31, 31}, hi[3] = {0, 0, 0};
    for (uint16_t k : box.colours) {
      for (int c = 0; c < 3; ++c) {
        lo[c] = std::min(lo[c], Channel(k, c));
        hi[c] = std::max(hi[c], Channel(k, c));
      }
    }
    int axis = 0;
    for (int c = 1; c < 3; ++c) {
      if (hi[c] - lo[c] > hi[axis] - lo[axis]) axis = c;
    }
    std::sort(box.colours.begin(), box.colours.end(), [axis](uint16_t a, uint16_t b) {
      return Channel(a, axis) != Channel(b, axis) ? Channel(a, axis) < Channel(b, axis) : a < b;
    });
    int64_t acc = 0;
    size_t cut = 1;
    for (size_t i = 0; i + 1 < box.colours.size(); ++i) {
      acc += hist[box.colours[i]];
      cut = i + 1;
      if (2 * acc >= box.weight) break;
    }
    Box upper;
    upper.colours.assign(box.colours.begin() + cut, box.colours.end());
    box.colours.resize(cut);
    box.weight = 0;
    for (uint16_t k : box.colours) box.weight += hist[k];
    for (uint16_t k : upper.colours) upper.weight += hist[k];
    boxes.push_back(std::move(upper));
  }
  for (const Box& box : boxes) {
    if (box.weight == 0) continue;
    double sum[3] = {0, 0, 0};
    for (uint16_t k : box.colours) {
      for (int c = 0; c < 3; ++c) sum[c] += hist[k] * (Channel(k, c) * 8 + 4);
    }
    std::array<uint8_t, 3> colour;
    for (int c = 0; c < 3; ++c) {
      colour[c] = static_cast<uint8_t>(std::clamp(std::lround(sum[c] / box.weight), 0L, 255L));
    }
    pal.colours_.push_back(colour);
  }
  while (pal.colours_.size() < 256) pal.colours_.push_back({0, 0, 0});
  pal.lut_.resize(32768);
  for (int key = 0; key < 32768; ++key) {
    const int r = Channel(key, 0) * 8 + 4, g = Channel(key, 1) * 8 + 4, b = Channel(key, 2) * 8 + 4;
    int best = 0, best_d = 1 << 30;
    for (int i = 0; i < 256; ++i) {
      const auto& p = pal.colours_[i];
      const int dr = r - p[0], dg = g - p[1], db = b - p[2];
      const int d = 2 * dr * dr + 4 * dg * dg + 3 * db * db;  // rough perceptual weights
      if (d < best_d) {
        best_d = d;
        best = i;
      }
    }
    pal.lut_[key] = static_cast<uint8_t>(best);
  }
  return pal;
}

GifWriter::~GifWriter() {
  sws_freeContext(sws_);
  av_frame_free(&pal_frame_);
  avcodec_free_context(&codec_);
}

Result<std::unique_ptr<GifWriter>> GifWriter::Open(const std::string& path, int in_width,
                                                   int in_height, int out_width,
                                                   double frame_seconds) {
  if (out_width < 16 || out_width > in_width) {
    return Error{"GIF width must be in [16, " + std::to_string(in_width) +
                 "] (the video width), got " + std::to_string(out_width)};
  }
  if (!(frame_seconds > 0)) return Error{"GIF frame duration must be positive"};
  const AVCodec* codec = avcodec_find_encoder(AV_CODEC_ID_GIF);
  if (!codec) return Error{"this libavcodec has no GIF encoder"};
  std::unique_ptr<GifWriter> w(new GifWriter());
  w->in_width_ = in_width;
  w->in_height_ = in_height;
  w->out_width_ = out_width;
  w->out_height_ = std::max(
      2, static_cast<int>(std::lround(static_cast<double>(in_height) * out_width / in_width)));
  w->frame_seconds_ = frame_seconds;
  auto output = LibavOutput::Open(path, "gif");
  if (!output.ok()) return Error{output.error(), output.code()};
  w->output_ = std::move(*output);

  w->codec_ = avcodec_alloc_context3(codec);
  if (!w->codec_) return Error{"out of memory"};
  w->codec_->width = w->out_width_;
  w->codec_->height = w->out_height_;
  w->codec_->pix_fmt = AV_PIX_FMT_PAL8;
  w->codec_->time_base = AVRational{1, 100};  // GIF delays are in 1/100 s
  int err = avcodec_open2(w->codec_, codec, nullptr);
  if (err < 0) return Error{"cannot open the GIF encoder: " + AvError(err), ErrorCode::kIo};
  if (Status s = w->output_->AddStream(w->codec_); !s.ok()) return Error{s.error(), s.code()};
  if (Status s = w->output_->WriteHeader(nullptr); !s.ok()) return Error{s.error(), s.code()};

  w->pal_frame_ = av_frame_alloc();
  if (!w->pal_frame_) return Error{"out of memory"};
  w->pal_frame_->format = AV_PIX_FMT_PAL8;
  w->pal_frame_->width = w->out_width_;
  w->pal_frame_->height = w->out_height_;
  err = av_frame_get_buffer(w->pal_frame_, 0);
  if (err < 0) return Error{"cannot allocate a GIF frame: " + AvError(err), AvCode(err)};
  w->sws_ = sws_getContext(in_width, in_height, AV_PIX_FMT_RGB24, w->out_width_, w->out_height_,
                           AV_PIX_FMT_RGB24, SWS_AREA, nullptr, nullptr, nullptr);
  if (!w->sws_) return Error{"cannot create the GIF scaler", ErrorCode::kIo};
  w->scaled_.resize(static_cast<size_t>(w->out_width_) * w->out_height_ * 3);
  return w;
}

Status GifWriter::Write(const Frame& frame) {
  if (frame.width != in_width_ || frame.height != in_height_) {
    return Error{"'" + path() + "': frame size changed during the video"};
  }
  const uint8_t* src[1] = {frame.TopRow()};
  const int src_stride[1] = {-3 * in_width_};
  uint8_t* dst[1] = {scaled_.data()};
  const int dst_stride[1] = {3 * out_width_};
  sws_scale(sws_, src, src_stride, 0, in_height_, dst, dst_stride);
  if (!palette_) {
    std::vector<std::array<uint8_t, 3>> reserved = {{255, 255, 255}, {0, 0, 0}};
    for (int i = 0; i <= 15; ++i) {
      const auto c = HeatColour(i / 15.0);
      reserved.push_back({static_cast<uint8_t>(std::lround(255 * c[0])),
                          static_cast<uint8_t>(std::lround(255 * c[1])),
                          static_cast<uint8_t>(std::lround(255 * c[2]))});
    }
    palette_ =
        std::make_unique<Palette>(Palette::FromImage(scaled_.data(), scaled_.size() / 3, reserved));
  }
  int err = av_frame_make_writable(pal_frame_);
  if (err < 0) return Error{"'" + path() + "': " + AvError(err), AvCode(err)};
  uint32_t* pal = reinterpret_cast<uint32_t*>(pal_frame_->data[1]);
  for (int i = 0; i < 256; ++i) {
    const auto& c = palette_->colours()[i];
    pal[i] = 0xFF000000u | (uint32_t{c[0]} << 16) | (uint32_t{c[1]} << 8) | c[2];
  }
  for (int y = 0; y < out_height_; ++y) {
    const unsigned char* in = scaled_.data() + static_cast<size_t>(y) * out_width_ * 3;
    uint8_t* out = pal_frame_->data[0] + static_cast<size_t>(y) * pal_frame_->linesize[0];
    for (int x = 0; x < out_width_; ++x)
      out[x] = palette_->Index(in[3 * x], in[3 * x + 1], in[3 * x + 2]);
  }
  pal_frame_->pts = std::llround(written_ * frame_seconds_ * 100.0);
  ++written_;
  return output_->Encode(pal_frame_);
}

Status GifWriter::Finish() { return output_->Finish(); }

}  // namespace recruit::render
