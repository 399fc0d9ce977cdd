#include "sim/format_g.h"

#include <fmt/format.h>

#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <utility>

#include "common/decimal_digits.h"

namespace recruit::sim {
namespace {

// s / 10^K for each K: division by a constant compiles to a multiply, not a divide.
template <std::size_t K>
std::uint64_t DivByPow10(std::uint64_t s) {
  return s / kPow10[K];
}
template <std::size_t... K>
constexpr std::array<std::uint64_t (*)(std::uint64_t), sizeof...(K)> DivTable(
    std::index_sequence<K...>) {
  return {&DivByPow10<K>...};
}
constexpr auto kDivByPow10 = DivTable(std::make_index_sequence<20>());

// s / 10^k and its remainder, k in 0..19.
std::uint64_t DivPow10(std::uint64_t s, int k, std::uint64_t* r) {
  const std::uint64_t q = kDivByPow10[k](s);
  *r = s - q * kPow10[k];
  return q;
}

constexpr char kDigitPairs[] =
    "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
    "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
    "8081828384858687888990919293949596979899";

// The n decimal digits of v (v < 10^n) at p[0..n), leading zeros included. Most values have at
// most 9 digits: their pairs come from 32-bit divisions, cheaper than 64-bit ones.
void WriteDigits(std::uint64_t v, int n, char* p) {
  char* end = p + n;
  while (v > 0xffffffffull) {
    end -= 2;
    std::memcpy(end, kDigitPairs + 2 * (v % 100), 2);
    v /= 100;
  }
  auto w = static_cast<std::uint32_t>(v);
  while (end - p >= 2) {
    end -= 2;
    std::memcpy(end, kDigitPairs + 2 * (w % 100), 2);
    w /= 100;
  }
  if (end > p) *--end = static_cast<char>('0' + w);
}

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

// The general case (and the rare ones the fast path leaves): fmt, which follows printf.
char* Slow(double x, int precision, char* out) {
  return fmt::format_to(out, "{:.{}g}", x, precision);
}

// Every case (FormatG calls it for what its fast path leaves). Most doubles at precision <= 9:
// RoundByScaling. Else the shortest decimal S that reads back as x (Dragonbox), of n digits. If
// n <= precision, S is also x rounded to `precision` digits: x is within half an ulp of S, far less
// than half a unit in the precision-th digit. If n >= precision + 2, rounding S gives the rounding
// of x: a rounding midpoint (precision + 1 digits) between x and S would be a shorter decimal that
// reads back as x. With n == precision + 1, S itself can be a midpoint: fmt decides.
__attribute__((noinline)) char* General(double x, int precision, char* out) {
  if (!std::isfinite(x) || precision < 1 || precision > 15) return Slow(x, precision, out);
  // (Subnormals too: their ulp is not small against the digits kept.)
  if (x != 0 && std::abs(x) < 2.2250738585072014e-308) return Slow(x, precision, out);
  if (std::signbit(x)) {
    *out++ = '-';
    x = -x;
  }
  if (x == 0) {
    *out++ = '0';
    return out;
  }
  std::uint64_t s;
  int e;
  const bool scaled = precision <= 9 && RoundByScaling(x, precision, &s, &e);
  if (scaled) {
    if (char* end = FixedForm(s, e, precision, out)) return end;
  } else {
    const auto dec = fmt::detail::dragonbox::to_decimal(x);
    s = dec.significand;
    e = dec.exponent;
    const int n = DecimalDigits(s);
    if (n == precision + 1) return Slow(x, precision, out);
    if (n > precision) {
      const std::uint64_t div = kPow10[n - precision];
      std::uint64_t r;
      std::uint64_t q = DivPow10(s, n - precision, &r);
      if (2 * r == div) return Slow(x, precision, out);  // a tie: not reached (see above)
      if (2 * r > div) ++q;
      e += n - precision;
      if (q == kPow10[precision]) {
        q = kPow10[precision - 1];
        ++e;
      }
      s = q;
    }
  }
  int n = DecimalDigits(s);
  while (s % 10 == 0) {  // %g drops trailing zeros
    s /= 10;
    ++e;
    --n;
  }
  const int X = n - 1 + e;         // the exponent of the leading digit
  if (X < -4 || X >= precision) {  // d.ddde+XX: the digits one place right, then the point
    WriteDigits(s, n, out + 1);
    out[0] = out[1];
    if (n > 1) {
      out[1] = '.';
      out += n + 1;
    } else {
      out += 1;
    }
    *out++ = 'e';
    *out++ = X < 0 ? '-' : '+';
    const int ax = X < 0 ? -X : X;
    if (ax < 100) {
      std::memcpy(out, kDigitPairs + 2 * ax, 2);
      return out + 2;
    }
    return std::to_chars(out, out + 4, ax).ptr;
  }
  if (X < 0) {  // 0.000ddd
    *out++ = '0';
    *out++ = '.';
    for (int i = 0; i < -X - 1; ++i) *out++ = '0';
    WriteDigits(s, n, out);
    return out + n;
  }
  if (n <= X + 1) {  // an integer: the digits, then zeros
    WriteDigits(s, n, out);
    out += n;
    for (int i = 0; i < X + 1 - n; ++i) *out++ = '0';
    return out;
  }
  // ddd.ddd: the X + 1 digits of the integer part, the point, the n - X - 1 of the fraction.
  std::uint64_t fraction;
  const std::uint64_t integer = DivPow10(s, n - X - 1, &fraction);
  WriteDigits(integer, X + 1, out);
  out[X + 1] = '.';
  WriteDigits(fraction, n - X - 1, out + X + 2);
  return out + n + 1;
}

}  // namespace

// The fast path alone (a normal double at precision <= 9 in fixed form: a CSV's every column)
// keeps the call short; the rest is General's.
char* FormatG(double x, int precision, char* out) {
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  const auto biased = static_cast<unsigned>(bits >> 52) & 0x7ff;
  if (biased - 1u < 2046u && static_cast<unsigned>(precision - 1) < 9u) {  // normal, 1..9
    *out = '-';  // kept only when negative
    std::uint64_t s;
    int e;
    if (RoundByScaling(std::abs(x), precision, &s, &e)) {
      if (char* end = FixedForm(s, e, precision, out + (bits >> 63))) return end;
    }
  }
  return General(x, precision, out);
}

char* FormatInt(long x, char* out) { return std::to_chars(out, out + 24, x).ptr; }

}  // namespace recruit::sim
