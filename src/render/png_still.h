// PNG stills (lodepng), written atomically.
#pragma once

#include <string>

#include "common/result.h"
#include "render/frame.h"

namespace recruit::render {

// Writes the frame top-down as an 8-bit RGB PNG at `path`.
Status WritePngStill(const Frame& frame, const std::string& path);

}  // namespace recruit::render
