// The SIL protocol (src/sil/protocol.h, docs/sil.md): the CRC's published check value, the
// documented example frames byte for byte, bit-exact round trips, and every refusal class:
// each single-bit error, each truncation, appended bytes, bad header fields, probabilities
// outside [0, 1]; the stream deframer recovers the frames from junk and split reads.
#include "sil/protocol.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

namespace recruit::sil {
namespace file_protocol_test {

std::string Hex(const std::vector<std::uint8_t>& b) {
  std::string s;
  char h[4];
  for (std::size_t i = 0; i < b.size(); ++i) {
    std::snprintf(h, sizeof h, i ? " %02X" : "%02X", b[i]);
    s += h;
  }
  return s;
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

Command SampleCommand(std::uint32_t seq) {
  Command c;
  c.sequence = seq;
  c.force_reference = {1.5, 0.25};
  c.p_on = {0.2, 0.0};
  c.p_off = {0.0, 1.0};
  c.estimated_on = {12.75, 3.0};
  c.variance = {0.5, std::numeric_limits<double>::quiet_NaN()};
  return c;
}

TEST(SilProtocol, Crc16HasTheCcittFalseCheckValue) {
  const char* s = "123456789";
  EXPECT_EQ(Crc16(reinterpret_cast<const std::uint8_t*>(s), 9), 0x29B1);
}

// The examples of docs/sil.md (bytes computed independently with Python's struct and a
// bitwise CRC).
TEST(SilProtocol, EncodesTheDocumentedExampleFrames) {
  EXPECT_EQ(Hex(EncodeHello(2, 1.0)), "5A 48 02 00 00 00 00 00 00 00 00 00 00 F0 3F B3 DE");
  EXPECT_EQ(Hex(EncodeEnd(1, 40)), "5A 45 01 28 00 00 00 DA D9");
  Measurement m;
  m.sequence = 3;
  m.time = 3.0;
  m.reference = 2.0;
  m.force = {1.875};
  m.length = {0.03125};
  EXPECT_EQ(Hex(EncodeMeasurement(m)),
            "5A 4D 01 03 00 00 00 00 00 00 00 00 00 08 40 00 00 00 00 00 00 00 40 00 00 00 00 00 "
            "00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 FE 3F 00 00 00 00 00 00 A0 3F A2 "
            "CA");
  Command c;
  c.sequence = 3;
  c.force_reference = {2.0};
  c.p_on = {0.25};
  c.p_off = {0.0};
  c.estimated_on = {10.0};
  c.variance = {0.5};
  EXPECT_EQ(Hex(EncodeCommand(c)),
            "5A 43 01 03 00 00 00 00 00 00 00 00 00 00 40 00 00 00 00 00 00 D0 3F 00 00 00 00 00 "
            "00 00 00 00 00 00 00 00 00 24 40 00 00 00 00 00 00 E0 3F BF E3");
}

TEST(SilProtocol, FramesRoundTripBitExactly) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 1 + trial % kMaxBundles;
    Measurement m;
    m.sequence = static_cast<std::uint32_t>(rng());
    auto any = [&] {
      std::uint64_t u = rng();
      double v;
      std::memcpy(&v, &u, sizeof v);  // every bit pattern: NaNs, infinities, subnormals
      return v;
    };
    m.time = any(), m.reference = any(), m.angle = any(), m.angular_velocity = any();
    for (int i = 0; i < n; ++i) m.force.push_back(any()), m.length.push_back(any());
    const auto bytes = EncodeMeasurement(m);
    ASSERT_EQ(bytes.size(), FrameSize('M', n));
    Frame f;
    ASSERT_EQ(ParseFrame(bytes.data(), bytes.size(), f), ParseError::kNone);
    EXPECT_EQ(f.type, FrameType::kMeasurement);
    EXPECT_EQ(f.measurement.sequence, m.sequence);
    EXPECT_TRUE(SameBits(f.measurement.reference, m.reference));
    EXPECT_TRUE(SameBits(f.measurement.angular_velocity, m.angular_velocity));
    for (int i = 0; i < n; ++i) {
      EXPECT_TRUE(SameBits(f.measurement.force[i], m.force[i]));
      EXPECT_TRUE(SameBits(f.measurement.length[i], m.length[i]));
    }
    Command c;
    c.sequence = m.sequence;
    std::uniform_real_distribution<double> u01(0, 1);
    for (int i = 0; i < n; ++i) {
      c.force_reference.push_back(any()), c.p_on.push_back(u01(rng)), c.p_off.push_back(u01(rng));
      c.estimated_on.push_back(any()), c.variance.push_back(any());
    }
    const auto cb = EncodeCommand(c);
    ASSERT_EQ(ParseFrame(cb.data(), cb.size(), f), ParseError::kNone);
    EXPECT_EQ(f.type, FrameType::kCommand);
    EXPECT_EQ(f.bundles, n);
    for (int i = 0; i < n; ++i) {
      EXPECT_TRUE(SameBits(f.command.p_on[i], c.p_on[i]));
      EXPECT_TRUE(SameBits(f.command.variance[i], c.variance[i]));
      EXPECT_TRUE(SameBits(f.command.force_reference[i], c.force_reference[i]));
    }
  }
}

// CRC-16 detects every single-bit error; a flipped header bit may be caught earlier (sync,
// type, count, length), never accepted.
TEST(SilProtocol, EverySingleBitErrorIsRefused) {
  const auto good = EncodeCommand(SampleCommand(42));
  for (std::size_t bit = 0; bit < 8 * good.size(); ++bit) {
    auto b = good;
    b[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
    Frame f;
    EXPECT_NE(ParseFrame(b.data(), b.size(), f), ParseError::kNone) << "bit " << bit;
  }
}

TEST(SilProtocol, TruncatedAndOversizedDatagramsAreNamed) {
  const auto good = EncodeCommand(SampleCommand(1));
  Frame f;
  for (std::size_t len = 0; len < good.size(); ++len) {
    EXPECT_EQ(ParseFrame(good.data(), len, f), ParseError::kTruncated) << len;
  }
  auto longer = good;
  longer.push_back(0);
  EXPECT_EQ(ParseFrame(longer.data(), longer.size(), f), ParseError::kOversized);
  std::vector<std::uint8_t> huge(4096, 0);
  std::copy(good.begin(), good.end(), huge.begin());
  EXPECT_EQ(ParseFrame(huge.data(), huge.size(), f), ParseError::kOversized);
}

// A frame with a valid CRC but a bad field: each is named.
TEST(SilProtocol, BadHeaderFieldsAndProbabilitiesAreRefused) {
  auto reseal = [](std::vector<std::uint8_t> b) {
    const std::uint16_t c = Crc16(b.data(), b.size() - 2);
    b[b.size() - 2] = c & 0xFF;
    b[b.size() - 1] = c >> 8;
    return b;
  };
  Frame f;
  auto b = EncodeCommand(SampleCommand(3));
  b[0] = 0xA5;
  EXPECT_EQ(ParseFrame(b.data(), b.size(), f), ParseError::kBadSync);
  b = EncodeCommand(SampleCommand(3));
  b[1] = 'X';
  b = reseal(b);
  EXPECT_EQ(ParseFrame(b.data(), b.size(), f), ParseError::kBadType);
  b = EncodeCommand(SampleCommand(3));
  b[2] = 0;
  EXPECT_EQ(ParseFrame(b.data(), b.size(), f), ParseError::kBadBundles);
  b[2] = kMaxBundles + 1;
  EXPECT_EQ(ParseFrame(b.data(), b.size(), f), ParseError::kBadBundles);
  b = EncodeHello(2, 1.0);
  b[3] = 1;  // a hello's sequence is 0
  b = reseal(b);
  EXPECT_EQ(ParseFrame(b.data(), b.size(), f), ParseError::kBadValue);
  for (double bad : {-1e-300, 1.0000000000000002, std::numeric_limits<double>::quiet_NaN(),
                     std::numeric_limits<double>::infinity()}) {
    Command c = SampleCommand(3);
    c.p_off[1] = bad;
    const auto e = EncodeCommand(c);
    EXPECT_EQ(ParseFrame(e.data(), e.size(), f), ParseError::kBadValue) << bad;
  }
}

// The stream: frames between junk bytes, a corrupted frame in the middle, fed in pieces of
// every size from 1 to 40 bytes: the valid frames come out in order, the corrupted one never.
TEST(SilProtocol, StreamDeframerRecoversFramesFromJunkAndSplitReads) {
  std::vector<std::uint8_t> stream = {0x00, 0x5A, 0x5A, 0x13, 0x37};
  std::vector<std::uint32_t> sent;
  for (std::uint32_t k = 0; k < 6; ++k) {
    auto b = EncodeCommand(SampleCommand(k));
    if (k == 3)
      b[20] ^= 0x04;  // corrupted: dropped
    else
      sent.push_back(k);
    stream.insert(stream.end(), b.begin(), b.end());
    if (k % 2 == 0) stream.insert(stream.end(), {0xFF, 0x5A, 0x48});
  }
  for (std::size_t piece = 1; piece <= 40; ++piece) {
    StreamDeframer d;
    std::vector<std::uint32_t> got;
    for (std::size_t at = 0; at < stream.size(); at += piece) {
      d.Append(stream.data() + at, std::min(piece, stream.size() - at));
      while (auto f = d.Next()) got.push_back(f->sequence);
    }
    EXPECT_EQ(got, sent) << "pieces of " << piece;
    EXPECT_GE(d.dropped_frames(), 1) << piece;
    EXPECT_LT(d.buffered(), kMaxFrameSize) << piece;
  }
}

}  // namespace file_protocol_test
}  // namespace recruit::sil
