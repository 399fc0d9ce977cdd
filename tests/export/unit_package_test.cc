// The unit side of the exported package (src/export/templates/recruit_unit.c, compiled into this
// test as shipped): the CRC and the generator against their published reference values, the
// wire format's round trip and error detection, and the units' draws against the binomial law.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <string>

#include "export/controller_export.h"

extern "C" {
#include "src/export/templates/recruit_unit.h"
}

namespace recruit::exporter {
namespace file_unit_package_test {

TEST(UnitPackage, IsTheTemplateCompiledHere) {
  const std::vector<ExportedFile> files = UnitPackage();
  ASSERT_EQ(files.size(), 2u);
  std::ifstream in(std::string(RECRUIT_SOURCE_DIR) + "/src/export/templates/recruit_unit.c");
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  EXPECT_EQ(files[1].name, "recruit_unit.c");
  EXPECT_EQ(files[1].contents, text);
}

TEST(UnitPackage, Crc8MatchesItsCatalogueCheckValue) {
  // CRC-8 (poly 0x07, init 0, no reflection, no xorout): check("123456789") = 0xF4.
  const uint8_t digits[] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
  EXPECT_EQ(recruit_crc8(digits, 9), 0xF4);
  EXPECT_EQ(recruit_crc8(digits, 0), 0x00);
}

TEST(UnitPackage, Pcg32MatchesTheReferenceImplementation) {
  // pcg32-demo (pcg-c-basic), pcg32_srandom_r(&rng, 42u, 54u): its first six outputs.
  recruit_pcg32 g;
  recruit_pcg32_seed(&g, 42u, 54u);
  const uint32_t want[] = {0xa15c02b7, 0x7b47f409, 0xba1d3330, 0x83d2f293, 0xbfa4784b, 0xcbed606e};
  for (uint32_t w : want) EXPECT_EQ(recruit_pcg32_next(&g), w);
}

TEST(UnitPackage, QuantizesProbabilitiesOntoTheWire) {
  EXPECT_EQ(recruit_wire_quantize(0.0f), 0);
  EXPECT_EQ(recruit_wire_quantize(1.0f), 32768);
  EXPECT_EQ(recruit_wire_quantize(0.5f), 16384);
  EXPECT_EQ(recruit_wire_quantize(0.2f), 6554);  // 6553.6 rounded
  EXPECT_EQ(recruit_wire_quantize(1.5f), 32768);
  EXPECT_EQ(recruit_wire_quantize(-0.1f), 0);
  EXPECT_EQ(recruit_wire_quantize(std::nanf("")), 0);
}

TEST(UnitPackage, FramesRoundTripAndEverySingleBitErrorIsCaught) {
  const recruit_wire_message m{3, 0xBEEF, 12345, 0};
  uint8_t frame[RECRUIT_WIRE_SIZE];
  recruit_wire_encode(&m, frame);
  EXPECT_EQ(frame[0], 0xA5);
  EXPECT_EQ(frame[2], 0xEF);  // little-endian
  EXPECT_EQ(frame[3], 0xBE);
  recruit_wire_message back{};
  ASSERT_EQ(recruit_wire_decode(frame, &back), 0);
  EXPECT_EQ(back.bundle, 3);
  EXPECT_EQ(back.sequence, 0xBEEF);
  EXPECT_EQ(back.p_on, 12345);
  EXPECT_EQ(back.p_off, 0);
  for (int bit = 0; bit < 8 * RECRUIT_WIRE_SIZE; ++bit) {
    uint8_t bad[RECRUIT_WIRE_SIZE];
    std::copy(frame, frame + RECRUIT_WIRE_SIZE, bad);
    bad[bit / 8] ^= static_cast<uint8_t>(1u << (bit % 8));
    EXPECT_LT(recruit_wire_decode(bad, &back), 0) << "bit " << bit;
  }
  // A valid checksum over a probability above 1 is refused too.
  const recruit_wire_message over{0, 1, 40000, 0};
  recruit_wire_encode(&over, frame);
  EXPECT_EQ(recruit_wire_decode(frame, &back), -3);
}

// The examples of docs/broadcast-wire-format.md.
TEST(UnitPackage, EncodesTheDocumentedExampleFrames) {
  uint8_t frame[RECRUIT_WIRE_SIZE];
  const recruit_wire_message a{0, 1, recruit_wire_quantize(0.2f), 0};
  recruit_wire_encode(&a, frame);
  const uint8_t want_a[] = {0xA5, 0x00, 0x01, 0x00, 0x9A, 0x19, 0x00, 0x00, 0xF5};
  EXPECT_TRUE(std::equal(frame, frame + RECRUIT_WIRE_SIZE, want_a));
  const recruit_wire_message b{1, 42, 0, recruit_wire_quantize(1.0f)};
  recruit_wire_encode(&b, frame);
  const uint8_t want_b[] = {0xA5, 0x01, 0x2A, 0x00, 0x00, 0x00, 0x00, 0x80, 0xFE};
  EXPECT_TRUE(std::equal(frame, frame + RECRUIT_WIRE_SIZE, want_b));
}

TEST(UnitPackage, UnitsTakeEachFrameOnceAndOnlyTheirBundles) {
  recruit_unit u;
  recruit_unit_init(&u, 1, 7, 0);
  uint8_t frame[RECRUIT_WIRE_SIZE];
  const recruit_wire_message sure_on{1, 10, RECRUIT_WIRE_ONE, 0};
  recruit_wire_encode(&sure_on, frame);
  EXPECT_EQ(recruit_unit_receive(&u, frame), 1);   // p_on = 1: on
  EXPECT_EQ(recruit_unit_receive(&u, frame), -5);  // the same frame again: ignored
  const recruit_wire_message other{2, 11, 0, RECRUIT_WIRE_ONE};
  recruit_wire_encode(&other, frame);
  EXPECT_EQ(recruit_unit_receive(&u, frame), -4);  // another bundle's
  const recruit_wire_message keep{1, 12, 0, 0};
  recruit_wire_encode(&keep, frame);
  EXPECT_EQ(recruit_unit_receive(&u, frame), 1);  // p_off = 0: stays on
  const recruit_wire_message off{1, 13, RECRUIT_WIRE_ONE, RECRUIT_WIRE_ONE};
  recruit_wire_encode(&off, frame);
  EXPECT_EQ(recruit_unit_receive(&u, frame), 0);  // an on unit reads p_off
}

// n units, each with its own stream, receive one frame: the number that switch is binomial(n,
// q / 32768); checked within 5 standard deviations, for p_on on off units, then p_off on the
// units that turned on.
TEST(UnitPackage, TheNumberSwitchingIsBinomialWithTheBroadcastProbability) {
  const int n = 20000;
  std::vector<recruit_unit> units(n);
  for (int i = 0; i < n; ++i) recruit_unit_init(&units[i], 0, 12345, static_cast<uint64_t>(i));
  const uint16_t q_on = recruit_wire_quantize(0.3f), q_off = recruit_wire_quantize(0.05f);
  uint8_t frame[RECRUIT_WIRE_SIZE];
  const recruit_wire_message on{0, 1, q_on, q_off};
  recruit_wire_encode(&on, frame);
  int now_on = 0;
  for (auto& u : units) now_on += recruit_unit_receive(&u, frame);
  const double p = q_on / 32768.0;
  EXPECT_NEAR(now_on, n * p, 5 * std::sqrt(n * p * (1 - p)));
  const recruit_wire_message off{0, 2, q_on, q_off};
  recruit_wire_encode(&off, frame);
  int turned_off = 0, was_on = now_on;
  for (auto& u : units) {
    const int before = u.on;
    const int after = recruit_unit_receive(&u, frame);
    turned_off += before == 1 && after == 0 ? 1 : 0;
  }
  const double r = q_off / 32768.0;
  EXPECT_NEAR(turned_off, was_on * r, 5 * std::sqrt(was_on * r * (1 - r)));
  // Same seeds and streams: the same draws.
  recruit_unit a, b;
  recruit_unit_init(&a, 0, 99, 5);
  recruit_unit_init(&b, 0, 99, 5);
  for (int k = 0; k < 100; ++k) EXPECT_EQ(recruit_pcg32_next(&a.rng), recruit_pcg32_next(&b.rng));
}

}  // namespace file_unit_package_test
}  // namespace recruit::exporter
