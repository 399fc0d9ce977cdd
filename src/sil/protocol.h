// The software-in-the-loop protocol of `recruit sil` (docs/sil.md): frames between the simulated
// plant and a controller. Every frame: sync 0x5A, type, bundle count n, sequence (uint32 LE, the
// control instant's index), a payload of IEEE-754 binary64 values (LE), CRC-16/CCITT-FALSE (LE)
// of everything before it. Parsing never trusts a length it has not checked.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace recruit::sil {

constexpr std::uint8_t kSync = 0x5A;
constexpr int kMaxBundles = 8;
constexpr std::size_t kHeaderSize = 7;  // sync, type, n, sequence
constexpr std::size_t kCrcSize = 2;

enum class FrameType : std::uint8_t {
  kHello = 'H',        // controller -> plant, once: "I am here, with n bundles and period dT"
  kMeasurement = 'M',  // plant -> controller, every control instant
  kCommand = 'C',      // controller -> plant, the answer to one measurement
  kEnd = 'E',          // plant -> controller: the run is over (sequence = instants run)
};

// Plant -> controller at control instant `sequence`: what recruit_input holds.
struct Measurement {
  std::uint32_t sequence = 0;
  double time = 0, reference = 0, angle = 0, angular_velocity = 0;
  std::vector<double> force, length;  // per bundle, N and m; NaN = lost sample
};

// Controller -> plant: the decision for instant `sequence`, per bundle (recruit_output).
struct Command {
  std::uint32_t sequence = 0;
  std::vector<double> force_reference, p_on, p_off, estimated_on, variance;
};

// One parsed frame; which member is meaningful follows `type`.
struct Frame {
  FrameType type = FrameType::kHello;
  int bundles = 0;
  std::uint32_t sequence = 0;
  double dT = 0;  // hello: the controller's period, s (0: not stated)
  Measurement measurement;
  Command command;
};

// Why a frame was refused (also the counter it goes to).
enum class ParseError {
  kNone,
  kTruncated,
  kOversized,
  kBadSync,
  kBadType,
  kBadBundles,
  kBadCrc,
  kBadValue
};
const char* ToString(ParseError e);

// CRC-16/CCITT-FALSE: polynomial 0x1021, initial 0xFFFF, no reflection, no final xor
// (check value of "123456789": 0x29B1).
std::uint16_t Crc16(const std::uint8_t* data, std::size_t size);

// The size of a frame of `type` with `bundles` bundles; 0 for an unknown type.
std::size_t FrameSize(std::uint8_t type, int bundles);
constexpr std::size_t kMaxFrameSize = kHeaderSize + 5 * 8 * kMaxBundles + kCrcSize;

std::vector<std::uint8_t> EncodeHello(int bundles, double dT);
std::vector<std::uint8_t> EncodeEnd(int bundles, std::uint32_t instants);
std::vector<std::uint8_t> EncodeMeasurement(const Measurement& m);
std::vector<std::uint8_t> EncodeCommand(const Command& c);

// Parses exactly one frame from `size` bytes (a datagram, or a candidate cut from a stream). A
// command's p_on and p_off must lie in [0, 1] and a hello's sequence be 0; any other value is
// taken as sent.
ParseError ParseFrame(const std::uint8_t* data, std::size_t size, Frame& out);

// Frames out of a byte stream (the pseudo-terminal): bytes are appended as they arrive; Next()
// returns the next complete frame. Bytes before a sync byte, and a candidate whose CRC fails
// (the sync byte is then skipped and the search resumes one byte later), are counted and dropped.
class StreamDeframer {
 public:
  void Append(const std::uint8_t* data, std::size_t size);
  // A frame, or nullopt when more bytes are needed.
  std::optional<Frame> Next();
  long dropped_bytes() const { return dropped_bytes_; }    // junk between frames
  long dropped_frames() const { return dropped_frames_; }  // candidates refused
  std::size_t buffered() const { return buffer_.size() - start_; }

 private:
  std::vector<std::uint8_t> buffer_;
  std::size_t start_ = 0;
  long dropped_bytes_ = 0, dropped_frames_ = 0;
};

}  // namespace recruit::sil
