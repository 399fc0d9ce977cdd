#include "sim/csv_writer.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iterator>

#include "common/decimal_digits.h"
#include "sim/format_g.h"

namespace recruit::sim {

CsvStepWriter::CsvStepWriter(std::string path, int every)
    : file_(std::move(path)), every_(every < 1 ? 1 : every) {
  buffer_.reserve(2 * kFlushBytes);
}

// The text of v (bits: its bits) if it differs from the column's last one only in the m last
// digits (Column): those are rewritten and true returned; else false, the column unchanged. The
// rounding is RoundByScaling's at the column's scale, so it gives FormatG's digits: q = base + low
// with 0 < low < span keeps the decade (the place of the point) and all but the m last digits.
inline __attribute__((always_inline)) bool CsvStepWriter::Step(Column& c, double v,
                                                               std::uint64_t bits, int precision) {
  const double y = v * c.scale;  // |v| 10^k (exact negation), < 0 if the sign changed
  const auto whole = static_cast<std::int64_t>(y);
  const double frac = y - static_cast<double>(whole);
  if (std::abs(frac - 0.5) < 1e-6) return false;  // near a midpoint: FormatG decides
  const std::uint64_t low = static_cast<std::uint64_t>(whole) + (frac > 0.5 ? 1 : 0) - c.base;
  if (low - 1 >= c.span1) return false;  // low == 0 (the point might go) or the prefix changed
  char* end = c.text() + c.full;
  if (precision <= 6) {
    // m <= 4: the m digits are the top m bytes of low's four; %g drops the zeros among them at
    // the end.
    const std::uint32_t digits = format_g_detail::FourDigits(static_cast<std::uint32_t>(low));
    const auto mask = static_cast<std::uint32_t>(c.mask >> 32);
    std::uint32_t w;
    std::memcpy(&w, end - 4, sizeof w);
    w = (w & ~mask) | (digits & mask);
    std::memcpy(end - 4, &w, sizeof w);
    c.len = static_cast<std::uint8_t>(c.full - (__builtin_clz((digits ^ 0x30303030u) & mask) >> 3));
  } else {
    // m <= 8: the same with low's eight digits.
    const std::uint64_t digits = format_g_detail::EightDigits(static_cast<std::uint32_t>(low));
    const std::uint64_t mask = c.mask;
    std::uint64_t w;
    std::memcpy(&w, end - 8, sizeof w);
    w = (w & ~mask) | (digits & mask);
    std::memcpy(end - 8, &w, sizeof w);
    c.len = static_cast<std::uint8_t>(
        c.full - (__builtin_clzll((digits ^ 0x3030303030303030ull) & mask) >> 3));
  }
  c.bits = bits;
  return true;
}

void CsvStepWriter::Format(Column& c, double v, std::uint64_t bits, int precision) {
  c.bits = bits;
  c.len = static_cast<std::uint8_t>(FormatG(v, precision, c.text()) - c.text());
  c.span1 = 0;  // no steps unless set below
  // The steps' state: the value's rounding as FormatG's fast path makes it (RoundByScaling), if
  // its text is in fixed form with a fraction (k >= 1 digits after the point) and 10^k exact.
  const auto biased = static_cast<unsigned>(bits >> 52) & 0x7ff;
  if (biased - 1u >= 2046u || precision < 2 || precision > 9) return;
  std::uint64_t s;
  int e;
  if (!format_g_detail::RoundByScaling(std::abs(v), precision, &s, &e)) return;
  const int X = e + precision - 1;  // the leading digit's exponent
  const int k = precision - 1 - X;  // digits after the point
  if (k < 1 || k > 22 || X < -4) return;
  // Step writes 4 digits at precisions <= 6 (the time, temperatures, estimates), else 8.
  const int m = std::min({k, precision - 1, precision <= 6 ? 4 : 8});
  const int full =
      static_cast<int>(bits >> 63) + (X >= 0 ? precision + 1 : precision + 1 - X);  // sign
  char* t = c.text();
  int n = c.len;
  if (n > full) return;
  // The trailing zeros %g dropped, and the point if it dropped all the fraction's digits.
  if (n < full && std::memchr(t, '.', static_cast<std::size_t>(n)) == nullptr) t[n++] = '.';
  while (n < full) t[n++] = '0';
  c.full = static_cast<std::uint8_t>(full);
  c.mask = ~0ull << (64 - 8 * m);
  c.scale = (bits >> 63) != 0 ? -format_g_detail::kExactPow10[k] : format_g_detail::kExactPow10[k];
  c.span1 = kPow10[m] - 1;
  c.base = s - s % kPow10[m];
}

Status CsvStepWriter::OnStep(const mjModel*, const mjData*, const TelemetrySample& s) {
  if (!file_.ok()) return Error{file_.error(), file_.code()};
  if (!header_written_) {
    std::string header = "time,reference,measured,angle";
    for (const auto& j : s.joints) header += fmt::format(",{0}.reference,{0}.angle", j.joint);
    for (const auto& b : s.bundles) {
      for (const char* col : {"force", "force_reference", "true_on", "estimated_on",
                              "estimated_on_std", "p_on", "p_off", "mean_temperature"}) {
        header += fmt::format(",{}.{}", b.actuator, col);
      }
    }
    header += ",control_instant";
    // Added after every older column, so that readers by position keep working.
    for (const auto& b : s.bundles) header += fmt::format(",{}.sensed_force", b.actuator);
    for (const auto& b : s.bundles) working_ = working_ || std::isfinite(b.estimated_working);
    if (working_) {
      for (const auto& b : s.bundles) header += fmt::format(",{}.estimated_working", b.actuator);
    }
    header += '\n';
    Reserve(header.size());
    std::memcpy(buffer_.data() + used_, header.data(), header.size());
    used_ += header.size();
    header_written_ = true;
  }
  if (every_ > 1 && count_++ % every_ != 0 && !s.control_instant) return Status::Ok();
  // The row is formatted in place, with room for the longest row (FormatG: "%.9g" etc. byte
  // for byte, without fmt's format-string parsing). Most columns hold between control instants
  // (references, estimates, broadcasts): a column equal to its last value reuses its text, and
  // one equal to the number formatted just before in the row (an angle task's measured value and
  // angle, a force task's measured value and force) copies that one's. Of the others most only
  // change their last digits (Column, `Step`).
  // The longest row and the columns' texts, sized when the layout is new (once in a run).
  if (s.joints.size() != joints_ || s.bundles.size() != bundles_ || row_max_ == 0) {
    joints_ = s.joints.size();
    bundles_ = s.bundles.size();
    row_max_ = 8 + (4 + 2 * joints_ + 10 * bundles_) * kFormatGMax;
    // A signalling NaN no arithmetic gives, with the text FormatG writes for any NaN: so the first
    // row needs no test of its own (a value with these very bits is still written right).
    Column unset;
    unset.bits = 0x7ff0dead0000beefull;
    unset.len = 3;
    std::memcpy(unset.text(), "nan", 3);
    cache_.assign(4 + 2 * joints_ + 10 * bundles_, unset);
    SlowColumns none;
    none.key[1] = ~0ull;  // no count's bits
    slow_.assign(bundles_, none);
  }
  Reserve(row_max_ + kSlowText);  // a copied SlowColumns text may move more than it keeps
  char* p = buffer_.data() + used_;
  Column* col = cache_.data();
  const Column* last = nullptr;  // the number formatted last in this row
  int last_precision = 0;
  // Inlined: an out-of-line call per number (18 per row of a two-bundle task) was ~1 % of an
  // arm run's CPU.
  auto num = [&](double v, int precision) __attribute__((always_inline)) {
    Column& c = *col++;
    std::uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    if (bits != c.bits) {
      if (last != nullptr && last->bits == bits && last_precision == precision) {
        c = *last;
      } else if (!Step(c, v, bits, precision)) {
        Format(c, v, bits, precision);
      }
      last = &c;
      last_precision = precision;
    }
    std::memcpy(p, c.text(), 16);  // fixed size: one move, the end is overwritten
    p += c.len;
  };
  // A count (a bundle's units on): its text cached like a number's, apart from `last`.
  auto count = [&](int v) __attribute__((always_inline)) {
    Column& c = *col++;
    const auto bits = static_cast<std::uint64_t>(static_cast<std::int64_t>(v));
    if (bits != c.bits) {
      c.bits = bits;
      c.len = static_cast<std::uint8_t>(FormatInt(v, c.text()) - c.text());
    }
    std::memcpy(p, c.text(), 16);
    p += c.len;
  };
  auto comma = [&p] { *p++ = ','; };
  num(s.time, 6);
  comma();
  num(s.reference, 9);
  comma();
  num(s.measured, 9);
  comma();
  num(s.angle, 9);
  for (const auto& j : s.joints) {
    comma();
    num(j.reference, 9);
    comma();
    num(j.angle, 9);
  }
  SlowColumns* slow = slow_.data();
  for (const auto& b : s.bundles) {
    comma();
    num(b.force, 9);
    comma();
    SlowColumns& g = *slow++;
    auto bits = [](double v) {
      std::uint64_t b;
      std::memcpy(&b, &v, sizeof b);
      return b;
    };
    if (((bits(b.force_reference) ^ g.key[0]) | (static_cast<std::uint32_t>(b.true_on) ^ g.key[1]) |
         (bits(b.estimated_on) ^ g.key[2]) | (bits(b.estimated_on_std) ^ g.key[3]) |
         (bits(b.p_on) ^ g.key[4]) | (bits(b.p_off) ^ g.key[5])) == 0) {
      // The columns' texts are those of the same values: copied as a whole, the cache unchanged.
      std::memcpy(p, g.text, kSlowText);
      p += g.len;
      col += 6;
    } else {
      char* const from = p;
      num(b.force_reference, 9);
      comma();
      count(b.true_on);
      comma();
      // Non-finite estimates (no estimator, no variance) are left empty: readers take them as NaN.
      if (std::isfinite(b.estimated_on)) {
        num(b.estimated_on, 6);
      } else {
        ++col;
      }
      comma();
      if (std::isfinite(b.estimated_on_std)) {
        num(b.estimated_on_std, 6);
      } else {
        ++col;
      }
      comma();
      num(b.p_on, 6);
      comma();
      num(b.p_off, 6);
      g.key[0] = bits(b.force_reference);
      g.key[1] = static_cast<std::uint32_t>(b.true_on);
      g.key[2] = bits(b.estimated_on);
      g.key[3] = bits(b.estimated_on_std);
      g.key[4] = bits(b.p_on);
      g.key[5] = bits(b.p_off);
      g.len = static_cast<std::size_t>(p - from);
      std::memcpy(g.text, from, kSlowText);
    }
    comma();
    num(b.mean_temperature, 6);
  }
  *p++ = ',';
  *p++ = s.control_instant ? '1' : '0';
  for (const auto& b : s.bundles) {
    comma();
    if (std::isfinite(b.sensed_force)) {
      num(b.sensed_force, 9);
    } else {
      ++col;
    }
  }
  for (std::size_t i = 0; working_ && i < s.bundles.size(); ++i) {
    comma();
    if (std::isfinite(s.bundles[i].estimated_working)) {
      num(s.bundles[i].estimated_working, 6);
    } else {
      ++col;
    }
  }
  *p++ = '\n';
  used_ = static_cast<std::size_t>(p - buffer_.data());
  if (used_ > kFlushBytes) Flush();
  return Status::Ok();
}

void CsvStepWriter::Flush() {
  file_.stream().write(buffer_.data(), static_cast<std::streamsize>(used_));
  used_ = 0;
}

Status CsvStepWriter::Finish() {
  if (!file_.ok()) return Error{file_.error(), file_.code()};
  Flush();
  return Status::Ok();
}

Status CsvStepWriter::Commit() {
  if (!file_.ok()) return Error{file_.error(), file_.code()};
  return file_.Commit();
}

}  // namespace recruit::sim
