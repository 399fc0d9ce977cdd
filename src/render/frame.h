// Frame: one rendered image as MuJoCo reads it (packed RGB, rows bottom-up), with its place in
// the video.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace recruit::render {

struct Frame {
  int width = 0;
  int height = 0;
  std::vector<unsigned char> rgb;  // width * height * 3, bottom row first
  int64_t index = 0;               // frame number in the video (pts in 1/fps units)
  double time = 0;                 // simulation time it shows, s
  std::string still_path;          // non-empty: also write this frame as a PNG still here

  void Resize(int w, int h) {
    width = w;
    height = h;
    rgb.resize(static_cast<size_t>(w) * h * 3);
  }
  // Pointer to the first byte of the top row (for writers that want top-down order).
  const unsigned char* TopRow() const {
    return rgb.data() + (static_cast<size_t>(height) - 1) * width * 3;
  }
};

}  // namespace recruit::render
