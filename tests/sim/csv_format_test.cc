// The per-step CSV's number formatting against its reference: FormatG must write what
// fmt's "{:.Ng}" (printf's "%.Ng") writes, and CsvStepWriter the rows the previous writer (fmt
// format strings, kept below) wrote, byte for byte.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <limits>
#include <random>

#include "common/atomic_file.h"
#include "sim/csv_writer.h"
#include "sim/format_g.h"

namespace recruit::sim {
namespace file_csv_format_test {

std::string Fast(double x, int precision) {
  char buf[kFormatGMax];
  return std::string(buf, FormatG(x, precision, buf));
}

TEST(FormatG, EqualsPrintfGForRandomDoublesOfEveryMagnitude) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> exponent(-320, 308);
  long checked = 0;
  for (int i = 0; i < 200000; ++i) {
    const double x = std::pow(10.0, exponent(rng)) * (rng() & 1 ? -1 : 1);
    std::uint64_t bits = rng();
    double any;
    std::memcpy(&any, &bits, sizeof any);  // any bit pattern, NaN and subnormals included
    // Short decimals and exact midpoints (x.5 at the digit after the precision).
    const double shortd = static_cast<double>(rng() % 100000000000ull) / std::pow(10.0, rng() % 14);
    const double mid =
        static_cast<double>((rng() % 2000000) * 2 + 1) * 5 / std::pow(10.0, rng() % 12);
    for (double v : {x, any, shortd, mid}) {
      for (int p : {6, 9, 1 + static_cast<int>(rng() % 17)}) {
        ASSERT_EQ(Fast(v, p), fmt::format("{:.{}g}", v, p)) << fmt::format("{:.17g} p={}", v, p);
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 2000000);
}

TEST(FormatG, EqualsPrintfGNearRoundingMidpointsAndDecades) {
  // x = (q + 1/2) 10^k with q of p digits, its neighbours, and values at and just below a power
  // of ten: where rounding by scaling must give up or carry into the next decade.
  std::mt19937_64 rng(11);
  for (int i = 0; i < 200000; ++i) {
    const int p = 1 + static_cast<int>(rng() % 9);
    const double q = static_cast<double>(rng() % static_cast<std::uint64_t>(std::pow(10, p)));
    const double scale = std::pow(10.0, static_cast<int>(rng() % 50) - 25);
    const double mid = (q + 0.5) * scale, top = (q + 1) * scale;
    for (double v : {mid, std::nextafter(mid, 0.0), std::nextafter(mid, 1e300), top,
                     std::nextafter(top, 0.0), scale * 9.99999999999, scale}) {
      for (int precision : {p, 6, 9}) {
        ASSERT_EQ(Fast(v, precision), fmt::format("{:.{}g}", v, precision))
            << fmt::format("{:.17g} p={}", v, precision);
      }
    }
  }
}

TEST(FormatG, EqualsPrintfGOnARunsTimeGridAndEveryLeadingDigitPattern) {
  // The fast path's digits come from one fixed-point product (NineDigits): every time on the
  // 2 ms grid of a 2000 s run as MuJoCo accumulates it, and integers and decimals whose digits
  // sweep every value at every position, with their trailing zeros dropped.
  double t = 0;
  for (int k = 0; k < 1000000; ++k) {
    t += 0.002;
    for (int p : {6, 9}) ASSERT_EQ(Fast(t, p), fmt::format("{:.{}g}", t, p)) << k;
  }
  std::mt19937_64 rng(5);
  for (int i = 0; i < 300000; ++i) {
    const double q = static_cast<double>(rng() % 1000000000ull + 1);
    for (double v : {q, q / 1e4, q / 1e9, q / 1e12}) {
      for (int p = 1; p <= 9; ++p) {
        ASSERT_EQ(Fast(v, p), fmt::format("{:.{}g}", v, p)) << fmt::format("{:.17g} p={}", v, p);
      }
    }
  }
}

TEST(FormatG, EqualsPrintfGAtTheEdges) {
  const double inf = std::numeric_limits<double>::infinity();
  for (double x : {0.0,
                   1.0,
                   0.1,
                   1e-5,
                   1e-4,
                   99999.95,
                   999999.5,
                   9999999.5,
                   999999999.5,
                   1e9,
                   1e15,
                   123456789.0,
                   0.5,
                   2.5,
                   1e300,
                   5e-324,
                   2.2250738585072014e-308,
                   1.7976931348623157e308,
                   1234567.5,
                   12345675.0,
                   0.000123456785,
                   inf,
                   std::numeric_limits<double>::quiet_NaN()}) {
    for (int p = 1; p <= 17; ++p) {
      EXPECT_EQ(Fast(x, p), fmt::format("{:.{}g}", x, p)) << x << " p=" << p;
      EXPECT_EQ(Fast(-x, p), fmt::format("{:.{}g}", -x, p)) << -x << " p=" << p;
    }
  }
}

TEST(FormatG, DigitWordsMatchPrintf) {
  // The CSV writer's tail digits (CsvStepWriter::Step): every 4-digit value, and 8-digit values
  // (every one below 10^6, a stride through the rest and random ones; every v < 10^8 was checked
  // once when they were written).
  char ref[16];
  for (std::uint32_t v = 0; v < 10000; ++v) {
    const std::uint32_t w = format_g_detail::FourDigits(v);
    std::snprintf(ref, sizeof ref, "%04u", v);
    ASSERT_EQ(std::memcmp(&w, ref, 4), 0) << v;
  }
  std::mt19937_64 rng(3);
  auto check8 = [&](std::uint32_t v) {
    const std::uint64_t w = format_g_detail::EightDigits(v);
    std::snprintf(ref, sizeof ref, "%08u", v);
    return std::memcmp(&w, ref, 8) == 0;
  };
  for (std::uint32_t v = 0; v < 1000000; ++v) ASSERT_TRUE(check8(v)) << v;
  for (std::uint32_t v = 1000000; v < 100000000; v += 37) ASSERT_TRUE(check8(v)) << v;
  for (int i = 0; i < 1000000; ++i) {
    const auto v = static_cast<std::uint32_t>(rng() % 100000000);
    ASSERT_TRUE(check8(v)) << v;
  }
}

// The row the previous writer formatted (fmt format strings), the reference.
std::string ReferenceRow(const TelemetrySample& s) {
  std::string row;
  auto out = std::back_inserter(row);
  fmt::format_to(out, "{:.6g},{:.9g},{:.9g},{:.9g}", s.time, s.reference, s.measured, s.angle);
  for (const auto& b : s.bundles) {
    fmt::format_to(out, ",{:.9g},{:.9g},{},", b.force, b.force_reference, b.true_on);
    if (std::isfinite(b.estimated_on)) fmt::format_to(out, "{:.6g}", b.estimated_on);
    row += ',';
    if (std::isfinite(b.estimated_on_std)) fmt::format_to(out, "{:.6g}", b.estimated_on_std);
    fmt::format_to(out, ",{:.6g},{:.6g},{:.6g}", b.p_on, b.p_off, b.mean_temperature);
  }
  fmt::format_to(out, ",{}", s.control_instant ? 1 : 0);
  for (const auto& b : s.bundles) {
    row += ',';
    if (std::isfinite(b.sensed_force)) fmt::format_to(out, "{:.9g}", b.sensed_force);
  }
  row += '\n';
  return row;
}

// The writer, finished and committed, wrote exactly `expected` to path (removed afterwards); on
// a difference, the first differing row (a whole-file EXPECT_EQ would print every row).
void ExpectWrites(CsvStepWriter& writer, const std::filesystem::path& path,
                  const std::string& expected) {
  ASSERT_TRUE(writer.Finish().ok());
  ASSERT_TRUE(writer.Commit().ok());
  auto text = ReadFile(path.string());
  ASSERT_TRUE(text.ok());
  ASSERT_EQ(text->size(), expected.size());
  std::size_t at = 0;
  while (at < expected.size() && (*text)[at] == expected[at]) ++at;
  EXPECT_EQ(at, expected.size()) << "differs in row: "
                                 << expected.substr(expected.rfind('\n', at) + 1, 200);
  std::filesystem::remove(path);
}

TEST(CsvStepWriter, WritesThePreviousWritersRowsByteForByte) {
  // Two bundles; values that hold for a few steps (the writer reuses a column's text), change,
  // and turn NaN (empty cells) and back.
  const auto path = std::filesystem::temp_directory_path() / "recruit_csv_format_test.csv";
  CsvStepWriter writer(path.string());
  TelemetrySample s;
  s.bundles.resize(2);
  s.bundles[0].actuator = "flexor";
  s.bundles[1].actuator = "extensor";
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0, 30);
  std::string expected =
      "time,reference,measured,angle,flexor.force,flexor.force_reference,flexor.true_on,"
      "flexor.estimated_on,flexor.estimated_on_std,flexor.p_on,flexor.p_off,"
      "flexor.mean_temperature,extensor.force,extensor.force_reference,extensor.true_on,"
      "extensor.estimated_on,extensor.estimated_on_std,extensor.p_on,extensor.p_off,"
      "extensor.mean_temperature,control_instant,flexor.sensed_force,extensor.sensed_force\n";
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int step = 0; step < 3000; ++step) {
    s.time = 0.002 * (step + 1);
    s.control_instant = step % 7 == 0;
    s.measured = n(rng);
    s.angle = n(rng) * 1e-3;
    if (s.control_instant) s.reference = std::round(n(rng));
    for (auto& b : s.bundles) {
      b.force = n(rng);
      b.mean_temperature = 20 + std::abs(n(rng));
      if (s.control_instant) {
        b.force_reference = n(rng);
        b.true_on = static_cast<int>(rng() % 61);
        b.estimated_on = step % 5 == 0 ? nan : std::abs(n(rng));
        b.estimated_on_std = step % 3 == 0 ? nan : std::abs(n(rng)) * 1e-3;
        b.p_on = std::abs(n(rng)) / 100;
        b.p_off = step % 2 ? 0.0 : -0.0;
        // The load cell's reading: none before the first instant, then quantised.
        b.sensed_force = step == 0 ? nan : 0.0125 * std::round(n(rng) / 0.0125);
      }
    }
    // Equal values in other columns of the row: the writer may copy the text it formatted just
    // before when the precision is the same, and must not when it differs.
    if (step % 4 == 1) s.angle = s.measured;
    if (step % 4 == 2) s.bundles[0].force = s.measured;
    if (step % 4 == 3) s.bundles[0].mean_temperature = s.bundles[0].force;  // %.6g after %.9g
    if (step % 8 == 5) s.bundles[1].force = s.bundles[0].mean_temperature;  // %.9g after %.6g
    if (step % 7 == 0 && step > 0)
      s.bundles[0].sensed_force = s.bundles[1].mean_temperature;  // the same
    ASSERT_TRUE(writer.OnStep(nullptr, nullptr, s).ok());
    expected += ReferenceRow(s);
  }
  ExpectWrites(writer, path, expected);
}

TEST(CsvStepWriter, SlowlyChangingValuesGiveThePreviousWritersRows) {
  // Values that change a little each step, as a run's do (the writer then rewrites only a
  // value's last digits): random walks of every relative step size, crossing zero (a sign
  // change), decades (the point moves) and values whose digits end in zeros; values near the
  // rounding midpoints of both precisions; the time on the 2 ms grid past 100 s; columns that
  // change only at instants, NaN estimates among them.
  const auto path = std::filesystem::temp_directory_path() / "recruit_csv_format_test_slow.csv";
  CsvStepWriter writer(path.string());
  TelemetrySample s;
  s.bundles.resize(2);
  s.bundles[0].actuator = "a";
  s.bundles[1].actuator = "b";
  std::mt19937_64 rng(17);
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> u(0, 1);
  std::string expected =
      "time,reference,measured,angle,a.force,a.force_reference,a.true_on,a.estimated_on,"
      "a.estimated_on_std,a.p_on,a.p_off,a.mean_temperature,b.force,b.force_reference,"
      "b.true_on,b.estimated_on,b.estimated_on_std,b.p_on,b.p_off,b.mean_temperature,"
      "control_instant,a.sensed_force,b.sensed_force\n";
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // The walks' values and step sizes (relative to a scale that changes now and then).
  double walk[6] = {10.7, -0.003, 57.9, 0.5, 99.99, 1e-4};
  double size[6] = {1e-6, 1e-5, 1e-4, 1e-3, 1e-7, 1e-2};
  s.time = 97.5;
  for (int step = 0; step < 40000; ++step) {
    s.time += 0.002;
    if (step % 500 == 0) {
      for (double& z : size) z = std::pow(10.0, -1 - 8 * u(rng));
    }
    for (int i = 0; i < 6; ++i) {
      walk[i] += size[i] * (std::abs(walk[i]) + 1e-3) * n(rng);
      // Now and then a value with trailing zeros, or one at or next to a rounding midpoint.
      if (rng() % 50 == 0) walk[i] = std::round(walk[i] * 100) / 100;
      if (rng() % 200 == 0) {
        const double scale =
            std::pow(10.0, (rng() % 2 ? 5 : 8) - std::floor(std::log10(std::abs(walk[i]) + 1e-9)));
        const double mid = (std::floor(walk[i] * scale) + 0.5) / scale;
        walk[i] = rng() % 2 ? mid : std::nextafter(mid, rng() % 2 ? 1e300 : -1e300);
      }
    }
    s.control_instant = step % 500 == 0;
    s.measured = walk[0];
    s.angle = walk[1];
    s.reference = walk[3];
    for (int k = 0; k < 2; ++k) {
      auto& b = s.bundles[k];
      b.force = k == 0 ? walk[0] : walk[4];
      b.mean_temperature = k == 0 ? walk[2] : walk[5] + 20;
      if (s.control_instant) {
        b.force_reference = walk[3] * 10;
        b.true_on = static_cast<int>(rng() % 61);
        b.estimated_on = step % 1500 == 0 ? nan : 30 * u(rng);
        b.estimated_on_std = 0.01 * u(rng);
        b.p_on = u(rng) / 10;
        b.p_off = step % 1000 ? 0.0 : -0.0;
        b.sensed_force = 0.0125 * std::round(walk[0] / 0.0125);
      }
    }
    ASSERT_TRUE(writer.OnStep(nullptr, nullptr, s).ok());
    expected += ReferenceRow(s);
  }
  ExpectWrites(writer, path, expected);
}

}  // namespace file_csv_format_test
}  // namespace recruit::sim
