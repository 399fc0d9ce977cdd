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
using format_g_detail::FixedForm;
using format_g_detail::kDigitPairs;
using format_g_detail::RoundByScaling;

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

// The general case (and the rare ones the fast path leaves): fmt, which follows printf.
char* Slow(double x, int precision, char* out) {
  return fmt::format_to(out, "{:.{}g}", x, precision);
}

}  // namespace

// Every case (FormatG calls it for what its fast path leaves). Most doubles at precision <= 9:
// RoundByScaling. Else the shortest decimal S that reads back as x (Dragonbox), of n digits. If
// n <= precision, S is also x rounded to `precision` digits: x is within half an ulp of S, far less
// than half a unit in the precision-th digit. If n >= precision + 2, rounding S gives the rounding
// of x: a rounding midpoint (precision + 1 digits) between x and S would be a shorter decimal that
// reads back as x. With n == precision + 1, S itself can be a midpoint: fmt decides.
char* FormatGGeneral(double x, int precision, char* out) {
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

char* FormatInt(long x, char* out) { return std::to_chars(out, out + 24, x).ptr; }

}  // namespace recruit::sim
