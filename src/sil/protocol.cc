#include "sil/protocol.h"

#include <cmath>
#include <cstring>

namespace recruit::sil {
namespace {

void PutU32(std::vector<std::uint8_t>& b, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
void PutDouble(std::vector<std::uint8_t>& b, double v) {
  std::uint64_t u;
  std::memcpy(&u, &v, sizeof u);
  for (int i = 0; i < 8; ++i) b.push_back(static_cast<std::uint8_t>(u >> (8 * i)));
}
std::uint32_t GetU32(const std::uint8_t* p) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(p[i]) << (8 * i);
  return v;
}
double GetDouble(const std::uint8_t* p) {
  std::uint64_t u = 0;
  for (int i = 0; i < 8; ++i) u |= static_cast<std::uint64_t>(p[i]) << (8 * i);
  double v;
  std::memcpy(&v, &u, sizeof v);
  return v;
}

std::vector<std::uint8_t> Header(FrameType type, int bundles, std::uint32_t sequence) {
  std::vector<std::uint8_t> b{kSync, static_cast<std::uint8_t>(type),
                              static_cast<std::uint8_t>(bundles)};
  PutU32(b, sequence);
  return b;
}

std::vector<std::uint8_t> Seal(std::vector<std::uint8_t> b) {
  const std::uint16_t crc = Crc16(b.data(), b.size());
  b.push_back(static_cast<std::uint8_t>(crc & 0xFF));
  b.push_back(static_cast<std::uint8_t>(crc >> 8));
  return b;
}

std::size_t PayloadValues(std::uint8_t type, int n) {
  switch (static_cast<FrameType>(type)) {
    case FrameType::kHello:
      return 1;
    case FrameType::kEnd:
      return 0;
    case FrameType::kMeasurement:
      return 4 + 2 * static_cast<std::size_t>(n);
    case FrameType::kCommand:
      return 5 * static_cast<std::size_t>(n);
  }
  return 0;
}

bool KnownType(std::uint8_t t) { return t == 'H' || t == 'M' || t == 'C' || t == 'E'; }

}  // namespace

const char* ToString(ParseError e) {
  switch (e) {
    case ParseError::kNone:
      return "ok";
    case ParseError::kTruncated:
      return "truncated";
    case ParseError::kOversized:
      return "oversized";
    case ParseError::kBadSync:
      return "bad sync byte";
    case ParseError::kBadType:
      return "unknown frame type";
    case ParseError::kBadBundles:
      return "bundle count out of range";
    case ParseError::kBadCrc:
      return "bad CRC";
    case ParseError::kBadValue:
      return "value out of range (a probability outside [0, 1], a hello's sequence not 0)";
  }
  return "?";
}

std::uint16_t Crc16(const std::uint8_t* data, std::size_t size) {
  std::uint16_t crc = 0xFFFF;
  for (std::size_t i = 0; i < size; ++i) {
    crc ^= static_cast<std::uint16_t>(data[i]) << 8;
    for (int b = 0; b < 8; ++b) {
      crc = (crc & 0x8000) ? static_cast<std::uint16_t>((crc << 1) ^ 0x1021)
                           : static_cast<std::uint16_t>(crc << 1);
    }
  }
  return crc;
}

std::size_t FrameSize(std::uint8_t type, int bundles) {
  if (!KnownType(type)) return 0;
  return kHeaderSize + 8 * PayloadValues(type, bundles) + kCrcSize;
}

std::vector<std::uint8_t> EncodeHello(int bundles, double dT) {
  std::vector<std::uint8_t> b = Header(FrameType::kHello, bundles, 0);
  PutDouble(b, dT);
  return Seal(std::move(b));
}

std::vector<std::uint8_t> EncodeEnd(int bundles, std::uint32_t instants) {
  return Seal(Header(FrameType::kEnd, bundles, instants));
}

std::vector<std::uint8_t> EncodeMeasurement(const Measurement& m) {
  const int n = static_cast<int>(m.force.size());
  std::vector<std::uint8_t> b = Header(FrameType::kMeasurement, n, m.sequence);
  for (double v : {m.time, m.reference, m.angle, m.angular_velocity}) PutDouble(b, v);
  for (int i = 0; i < n; ++i) PutDouble(b, m.force[i]);
  for (int i = 0; i < n; ++i)
    PutDouble(b, i < static_cast<int>(m.length.size()) ? m.length[i] : NAN);
  return Seal(std::move(b));
}

std::vector<std::uint8_t> EncodeCommand(const Command& c) {
  const int n = static_cast<int>(c.p_on.size());
  std::vector<std::uint8_t> b = Header(FrameType::kCommand, n, c.sequence);
  for (int i = 0; i < n; ++i) {
    for (const std::vector<double>* f :
         {&c.force_reference, &c.p_on, &c.p_off, &c.estimated_on, &c.variance}) {
      PutDouble(b, i < static_cast<int>(f->size()) ? (*f)[i] : NAN);
    }
  }
  return Seal(std::move(b));
}

ParseError ParseFrame(const std::uint8_t* data, std::size_t size, Frame& out) {
  if (size >= 1 && data[0] != kSync) return ParseError::kBadSync;
  if (size < kHeaderSize + kCrcSize) return ParseError::kTruncated;
  if (size > kMaxFrameSize) return ParseError::kOversized;
  if (!KnownType(data[1])) return ParseError::kBadType;
  const int n = data[2];
  if (n < 1 || n > kMaxBundles) return ParseError::kBadBundles;
  const std::size_t want = FrameSize(data[1], n);
  if (size < want) return ParseError::kTruncated;
  if (size > want) return ParseError::kOversized;
  const std::uint16_t crc = static_cast<std::uint16_t>(data[want - 2] | (data[want - 1] << 8));
  if (Crc16(data, want - 2) != crc) return ParseError::kBadCrc;
  Frame f;
  f.type = static_cast<FrameType>(data[1]);
  f.bundles = n;
  f.sequence = GetU32(data + 3);
  const std::uint8_t* p = data + kHeaderSize;
  if (f.type == FrameType::kHello) {
    if (f.sequence != 0) return ParseError::kBadValue;
    f.dT = GetDouble(p);
  } else if (f.type == FrameType::kMeasurement) {
    Measurement& m = f.measurement;
    m.sequence = f.sequence;
    m.time = GetDouble(p);
    m.reference = GetDouble(p + 8);
    m.angle = GetDouble(p + 16);
    m.angular_velocity = GetDouble(p + 24);
    for (int i = 0; i < n; ++i) m.force.push_back(GetDouble(p + 32 + 8 * i));
    for (int i = 0; i < n; ++i) m.length.push_back(GetDouble(p + 32 + 8 * (n + i)));
  } else if (f.type == FrameType::kCommand) {
    Command& c = f.command;
    c.sequence = f.sequence;
    for (int i = 0; i < n; ++i, p += 40) {
      c.force_reference.push_back(GetDouble(p));
      c.p_on.push_back(GetDouble(p + 8));
      c.p_off.push_back(GetDouble(p + 16));
      c.estimated_on.push_back(GetDouble(p + 24));
      c.variance.push_back(GetDouble(p + 32));
      // Written so that NaN fails too.
      if (!(c.p_on[i] >= 0 && c.p_on[i] <= 1 && c.p_off[i] >= 0 && c.p_off[i] <= 1)) {
        return ParseError::kBadValue;
      }
    }
  }
  out = std::move(f);
  return ParseError::kNone;
}

void StreamDeframer::Append(const std::uint8_t* data, std::size_t size) {
  // Compact before growing: the buffer never holds more than one partial frame plus `size`.
  if (start_ > 0) {
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(start_));
    start_ = 0;
  }
  buffer_.insert(buffer_.end(), data, data + size);
}

std::optional<Frame> StreamDeframer::Next() {
  while (start_ < buffer_.size()) {
    const std::uint8_t* p = buffer_.data() + start_;
    const std::size_t avail = buffer_.size() - start_;
    if (p[0] != kSync) {
      ++dropped_bytes_;
      ++start_;
      continue;
    }
    if (avail < 3) return std::nullopt;
    const std::size_t want = (p[2] >= 1 && p[2] <= kMaxBundles) ? FrameSize(p[1], p[2]) : 0;
    if (want == 0) {  // not a frame header: skip the sync byte
      ++dropped_frames_;
      ++start_;
      continue;
    }
    if (avail < want) return std::nullopt;
    Frame f;
    if (ParseFrame(p, want, f) == ParseError::kNone) {
      start_ += want;
      return f;
    }
    ++dropped_frames_;
    ++start_;
  }
  return std::nullopt;
}

}  // namespace recruit::sil
