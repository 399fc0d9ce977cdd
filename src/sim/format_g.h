// FormatG: a double as printf("%.<precision>g") writes it (and fmt's "{:.<precision>g}"), byte
// for byte, at about a fifth of fmt's cost (bench/sim/format_g_bench.cc): the per-step CSV of
// `recruit simulate` formats ~6 new numbers per physics step.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "common/decimal_digits.h"

namespace recruit::sim {

// Longest text FormatG writes ("-1.2345678901234567e-308").
inline constexpr std::size_t kFormatGMax = 32;

// Every case of FormatG (its fast path's rare misses, other precisions, exponent form, zero,
// non-finite and subnormal values).
char* FormatGGeneral(double x, int precision, char* out);

namespace format_g_detail {

constexpr char kDigitPairs[] =
    "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
    "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
    "8081828384858687888990919293949596979899";

constexpr double kExactPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                  1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                  1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

// x > 0 (normal) rounded to `precision` (1..9) significant digits as s 10^e, s of `precision`
// digits, without Dragonbox: y = x 10^k in one correctly rounded operation (10^k exact for |k| <=
// 22) is within 2^-24 of the exact product (y < 2^30), so rounding y to an integer rounds the exact
// product the same way unless y is within 1e-6 of a midpoint (then false: the caller decides).
inline __attribute__((always_inline)) bool RoundByScaling(double x, int precision, std::uint64_t* s,
                                                          int* e) {
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  const int e2 = static_cast<int>((bits >> 52) & 0x7ff) - 1023;
  int X = (e2 * 1233) >> 12;  // ~ floor(e2 log10 2): the leading digit's exponent or one below
  for (int attempt = 0; attempt < 3; ++attempt) {
    const int k = precision - 1 - X;
    if (k < -22 || k > 22) return false;
    const double y = k >= 0 ? x * kExactPow10[k] : x / kExactPow10[-k];
    // y < 10^(precision + 1) (X is the leading digit's exponent or one below): truncation is
    // floor, one instruction where std::floor is a libm call on the portable instruction set.
    const auto whole = static_cast<std::uint64_t>(static_cast<std::int64_t>(y));
    if (whole < kPow10[precision - 1]) {  // X too high
      --X;
      continue;
    }
    if (whole >= kPow10[precision]) {  // X too low
      ++X;
      continue;
    }
    const double frac = y - static_cast<double>(whole);  // exact
    if (std::abs(frac - 0.5) < 1e-6) return false;
    std::uint64_t q = whole + (frac > 0.5 ? 1 : 0);
    if (q == kPow10[precision]) {  // rounded up into the next decade
      q = kPow10[precision - 1];
      ++X;
    }
    *s = q;
    *e = X - (precision - 1);
    return true;
  }
  return false;
}

// The 9 decimal digits of v, 10^8 <= v < 10^9, at p[0..9): y is v 2^32 / 10^8 in fixed point
// (jeaiii's constants, checked for every v < 10^9), so the integer part is the first digit and
// each multiplication of the fraction by 100 moves the next pair into the integer part: a multiply
// per pair, where divisions by constants cost two multiplies and a subtraction each.
inline __attribute__((always_inline)) void NineDigits(std::uint32_t v, char* p) {
  std::uint64_t y = (v * 2882303762ull >> 26) + 4;
  p[0] = static_cast<char>('0' + (y >> 32));
  y = (y & 0xffffffffu) * 100;
  std::memcpy(p + 1, kDigitPairs + 2 * (y >> 32), 2);
  y = (y & 0xffffffffu) * 100;
  std::memcpy(p + 3, kDigitPairs + 2 * (y >> 32), 2);
  y = (y & 0xffffffffu) * 100;
  std::memcpy(p + 5, kDigitPairs + 2 * (y >> 32), 2);
  y = (y & 0xffffffffu) * 100;
  std::memcpy(p + 7, kDigitPairs + 2 * (y >> 32), 2);
}

// The 8 decimal digits of v < 10^8 (leading zeros included) as ASCII in one word, the first digit
// in its lowest byte (the order they have in memory): the two halves of 4 digits, their pairs and
// then their digits split in all lanes at once by multiply-shift divisions (exact in each lane's
// range; checked for every v < 10^8). About 20 instructions, without a table.
inline __attribute__((always_inline)) std::uint64_t EightDigits(std::uint32_t v) {
  const std::uint64_t merged = (v / 10000) | (static_cast<std::uint64_t>(v % 10000) << 32);
  const std::uint64_t top = ((merged * 10486ull) >> 20) & ((0x7full << 32) | 0x7full);  // / 100
  const std::uint64_t hundreds = ((merged - 100ull * top) << 16) + top;
  std::uint64_t tens = ((hundreds * 103ull) >> 10) & 0x000f000f000f000full;  // / 10
  tens += (hundreds - 10ull * tens) << 8;
  return tens + 0x3030303030303030ull;
}

// The 4 decimal digits of v < 10^4 likewise, in the low 4 bytes: EightDigits's last two stages on
// one half (checked for every v < 10^4).
inline __attribute__((always_inline)) std::uint32_t FourDigits(std::uint32_t v) {
  const std::uint32_t top = (v * 10486u) >> 20;  // v / 100
  const std::uint32_t hundreds = ((v - 100 * top) << 16) + top;
  std::uint32_t tens = ((hundreds * 103u) >> 10) & 0x000f000fu;  // / 10 in each half
  tens += (hundreds - 10 * tens) << 8;
  return tens + 0x30303030u;
}

// s (exactly `precision` <= 9 digits) x 10^e in %g's fixed form, if its leading digit's exponent
// X is in -4..precision-1 (else nullptr): the digits, trailing zeros dropped, around the point.
// Moves are 16 bytes of constant size (one instruction each); out has kFormatGMax bytes.
inline __attribute__((always_inline)) char* FixedForm(std::uint64_t s, int e, int precision,
                                                      char* out) {
  const int X = e + precision - 1;
  if (X < -4 || X >= precision) return nullptr;
  char d[32] = {};
  // s with 9 - precision zeros appended: always 9 digits, none of them leading zeros.
  NineDigits(static_cast<std::uint32_t>(s * kPow10[9 - precision]), d);
  // %g drops trailing zeros: the '0' bytes among d[1..9) at the top of the little-endian word.
  std::uint64_t w;
  std::memcpy(&w, d + 1, 8);
  w ^= 0x3030303030303030ull;
  const int n = w == 0 ? 1 : 9 - (__builtin_clzll(w) >> 3);
  if (X < 0) {  // 0.000ddd
    std::memcpy(out, "0.000000", 8);
    std::memcpy(out + 1 - X, d, 16);
    return out + 1 - X + n;
  }
  std::memcpy(out, d, 16);
  if (n <= X + 1) return out + X + 1;  // an integer (its zeros are digits of s)
  out[X + 1] = '.';
  std::memcpy(out + X + 2, d + X + 1, 16);
  return out + n + 1;
}

}  // namespace format_g_detail

// Writes `x` into `out` (room for kFormatGMax chars, which it may use as scratch past the text) as
// "%.<precision>g" (fast for precision 1..15, any other through fmt); returns the end of the text
// (not terminated). The fast path (a normal double at precision <= 9 in fixed form: a CSV's every
// column) is inline, so that a writer formatting a row keeps its state in registers; the rest is
// FormatGGeneral's.
inline __attribute__((always_inline)) char* FormatG(double x, int precision, char* out) {
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  const auto biased = static_cast<unsigned>(bits >> 52) & 0x7ff;
  if (biased - 1u < 2046u && static_cast<unsigned>(precision - 1) < 9u) {  // normal, 1..9
    *out = '-';  // kept only when negative
    std::uint64_t s;
    int e;
    if (format_g_detail::RoundByScaling(std::abs(x), precision, &s, &e)) {
      if (char* end = format_g_detail::FixedForm(s, e, precision, out + (bits >> 63))) return end;
    }
  }
  return FormatGGeneral(x, precision, out);
}

// A non-negative or negative integer in decimal; returns the end.
char* FormatInt(long x, char* out);

}  // namespace recruit::sim
