// GifWriter: an animated GIF for reports and READMEs. Frames are scaled down (libswscale, area
// filter) and mapped to one global 256-colour palette: median cut over the first frame's
// colours, plus reserved entries for the tendon heat ramp and white/black, so colours that
// appear later (a hot tendon) still map well. One palette for the whole clip keeps static
// regions identical between frames, which lets the GIF encoder store only what changed.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "common/result.h"
#include "render/frame.h"
#include "render/libav_output.h"

struct AVCodecContext;
struct AVFrame;
struct SwsContext;

namespace recruit::render {

// A 256-entry palette with a 15-bit (RGB555) nearest-colour lookup table.
class Palette {
 public:
  // Median cut over `rgb` (packed RGB, any order), `reserved` colours added first.
  static Palette FromImage(const unsigned char* rgb, size_t pixels,
                           const std::vector<std::array<uint8_t, 3>>& reserved);
  uint8_t Index(uint8_t r, uint8_t g, uint8_t b) const {
    return lut_[((r >> 3) << 10) | ((g >> 3) << 5) | (b >> 3)];
  }
  const std::vector<std::array<uint8_t, 3>>& colours() const { return colours_; }

 private:
  std::vector<std::array<uint8_t, 3>> colours_;
  std::vector<uint8_t> lut_;  // 32768 entries
};

class GifWriter {
 public:
  // The GIF is `out_width` wide (height keeps the aspect ratio); frames are shown for
  // `frame_seconds` each (rounded to GIF's 1/100 s ticks without drifting).
  static Result<std::unique_ptr<GifWriter>> Open(const std::string& path, int in_width,
                                                 int in_height, int out_width,
                                                 double frame_seconds);
  ~GifWriter();
  GifWriter(const GifWriter&) = delete;
  GifWriter& operator=(const GifWriter&) = delete;

  Status Write(const Frame& frame);
  Status Finish();
  const std::string& path() const { return output_->path(); }
  int width() const { return out_width_; }
  int height() const { return out_height_; }

 private:
  GifWriter() = default;

  std::unique_ptr<LibavOutput> output_;
  AVCodecContext* codec_ = nullptr;
  AVFrame* pal_frame_ = nullptr;
  SwsContext* sws_ = nullptr;
  int in_width_ = 0, in_height_ = 0, out_width_ = 0, out_height_ = 0;
  double frame_seconds_ = 0.1;
  int64_t written_ = 0;
  std::vector<unsigned char> scaled_;
  std::unique_ptr<Palette> palette_;
};

}  // namespace recruit::render
