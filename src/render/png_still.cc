#include "render/png_still.h"

#include <lodepng.h>

#include <cstring>
#include <vector>

#include "common/atomic_file.h"

namespace recruit::render {

Status WritePngStill(const Frame& frame, const std::string& path) {
  const size_t row = static_cast<size_t>(frame.width) * 3;
  std::vector<unsigned char> top_down(row * frame.height);
  for (int y = 0; y < frame.height; ++y) {
    std::memcpy(top_down.data() + row * y, frame.rgb.data() + row * (frame.height - 1 - y), row);
  }
  std::vector<unsigned char> png;
  const unsigned err = lodepng::encode(png, top_down, frame.width, frame.height, LCT_RGB, 8);
  if (err) return Error{"PNG still '" + path + "': " + lodepng_error_text(err)};
  return WriteFileAtomically(path, std::string(png.begin(), png.end()));
}

}  // namespace recruit::render
