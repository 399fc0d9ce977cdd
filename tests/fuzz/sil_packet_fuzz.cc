// Fuzz target: the `recruit sil` packet parser (src/sil/protocol.h, docs/sil.md). The input is
// taken as one datagram (ParseFrame) and as a byte stream fed to StreamDeframer in pieces whose
// sizes byte 0 sets. Every frame accepted must re-encode to the bytes it came from (a parse that
// invents or loses a value traps), and the deframer's buffer stays bounded.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "sil/protocol.h"

namespace {

using namespace recruit::sil;

std::vector<std::uint8_t> Reencode(const Frame& f) {
  switch (f.type) {
    case FrameType::kHello:
      return EncodeHello(f.bundles, f.dT);
    case FrameType::kEnd:
      return EncodeEnd(f.bundles, f.sequence);
    case FrameType::kMeasurement:
      return EncodeMeasurement(f.measurement);
    case FrameType::kCommand:
      return EncodeCommand(f.command);
  }
  __builtin_trap();
}

void CheckSame(const Frame& f, const std::uint8_t* data, std::size_t size) {
  const std::vector<std::uint8_t> again = Reencode(f);
  if (again.size() != size || std::memcmp(again.data(), data, size) != 0) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  Frame f;
  if (ParseFrame(data, size, f) == ParseError::kNone) CheckSame(f, data, size);
  if (size < 1) return 0;
  const std::size_t piece = 1 + data[0] % 64;
  StreamDeframer d;
  std::size_t consumed = 0;
  for (std::size_t at = 1; at < size; at += piece) {
    d.Append(data + at, std::min(piece, size - at));
    consumed = std::min(at + piece, size);
    while (std::optional<Frame> g = d.Next()) {
      // The frame's bytes end where the deframer stopped: re-encoding must find them there.
      const std::vector<std::uint8_t> again = Reencode(*g);
      const std::size_t end = consumed - d.buffered();
      if (again.size() > end - 1 ||
          std::memcmp(again.data(), data + end - again.size(), again.size()) != 0) {
        __builtin_trap();
      }
    }
    if (d.buffered() > kMaxFrameSize + 64) __builtin_trap();
  }
  return 0;
}
