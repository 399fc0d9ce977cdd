#include "estimation/shortest_double.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "common/decimal_digits.h"

namespace recruit::estimation {
namespace {

constexpr char kDigitPairs[] =
    "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
    "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
    "8081828384858687888990919293949596979899";

// The eight decimal digits of c < 10^8 (leading zeros included) as eight characters in
// memory order (little-endian), in SIMD-within-a-register arithmetic: two 4-digit halves, then
// four 2-digit lanes, then eight bytes.
inline uint64_t Eight(uint32_t c) {
  uint64_t x = (c / 10000) | (static_cast<uint64_t>(c % 10000) << 32);
  const uint64_t q = ((x * 10486) >> 20) & 0x0000007F0000007Full;  // each half / 100
  x = q | ((x - q * 100) << 16);
  const uint64_t t = ((x * 103) >> 10) & 0x000F000F000F000Full;  // each lane / 10
  x = t | ((x - t * 10) << 8);
  return x | 0x3030303030303030ull;
}

inline void Store8(char* p, uint64_t x) {
  if constexpr (__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__) {
    std::memcpy(p, &x, 8);
  } else {
    for (int i = 0; i < 8; ++i) p[i] = static_cast<char>(x >> (8 * i));
  }
}

// The n <= 24 decimal digits of v at out[0..n) with whole 8-byte stores straight into the
// output (no staging buffer, whose reloads would stall on store forwarding): the leading k
// digits are the last k of an eight-digit chunk, shifted down. Writes up to out + n + 7.
void WriteDigits(char* out, uint64_t v, int n) {
  if (n <= 8) {
    Store8(out, Eight(static_cast<uint32_t>(v)) >> (8 * (8 - n)));
    return;
  }
  const uint32_t lo = static_cast<uint32_t>(v % 100000000u);
  v /= 100000000u;
  if (n <= 16) {
    const int k = n - 8;
    Store8(out, Eight(static_cast<uint32_t>(v)) >> (8 * (8 - k)));
    Store8(out + k, Eight(lo));
    return;
  }
  const int k = n - 16;
  Store8(out, Eight(static_cast<uint32_t>(v / 100000000u)) >> (8 * (8 - k)));
  Store8(out + k, Eight(static_cast<uint32_t>(v % 100000000u)));
  Store8(out + k + 8, Eight(lo));
}

}  // namespace

char* WriteShortest(char* p, double v) {
  if (!std::isfinite(v) || v == 0.0) {
    return std::to_chars(p, p + kShortestDoubleMaxChars, v).ptr;  // rare: the library's form
  }
  if (std::signbit(v)) {
    *p++ = '-';
    v = -v;
  }
  // v = sig 10^e with the fewest digits that read back to v (the nearest such when several).
  const auto dec = fmt::detail::dragonbox::to_decimal(v);
  uint64_t sig = dec.significand;
  int e = dec.exponent;
  while (sig % 10 == 0) {  // Dragonbox already removes them; kept for safety
    sig /= 10;
    ++e;
  }
  const int n = DecimalDigits(sig);
  // std::to_chars's choice: scientific d[.ddd]e(+|-)XX[X] or fixed, the shorter, fixed on a tie.
  const int sci_exp = e + n - 1;
  const int abs_sci = sci_exp < 0 ? -sci_exp : sci_exp;
  const int sci_len = n + (n > 1) + 2 + (abs_sci >= 100 ? 3 : 2);
  int fixed_len;
  if (e >= 0) {
    fixed_len = n + e;  // digits, then e zeros
  } else if (n + e > 0) {
    fixed_len = n + 1;  // a point inside the digits
  } else {
    fixed_len = 2 + (-(n + e)) + n;  // "0." zeros digits
  }
  if (fixed_len <= sci_len) {
    if (e >= 0) {
      // std::to_chars writes the exact integer, whose digits differ from the shortest ones
      // followed by zeros from 2^53 on (below, every integer is a double).
      if (v >= 9007199254740992.0) {
        return std::to_chars(p, p + kShortestDoubleMaxChars, v, std::chars_format::fixed).ptr;
      }
      WriteDigits(p, sig, n);
      p += n;
      for (int i = 0; i < e; ++i) *p++ = '0';
      return p;
    }
    const int point = n + e;
    if (point > 0) {  // the digits one place on, then the integer part moved back before '.'
      WriteDigits(p + 1, sig, n);
      for (int i = 0; i < point; ++i) p[i] = p[i + 1];
      p[point] = '.';
      return p + n + 1;
    }
    *p++ = '0';
    *p++ = '.';
    for (int i = 0; i < -point; ++i) *p++ = '0';
    WriteDigits(p, sig, n);
    return p + n;
  }
  WriteDigits(p + 1, sig, n);  // the first digit moved back before the point
  p[0] = p[1];
  if (n > 1) {
    p[1] = '.';
    p += n + 1;
  } else {
    p += 1;
  }
  *p++ = 'e';
  *p++ = sci_exp < 0 ? '-' : '+';
  if (abs_sci >= 100) {
    *p++ = static_cast<char>('0' + abs_sci / 100);
    const int r = abs_sci % 100;
    *p++ = kDigitPairs[2 * r];
    *p++ = kDigitPairs[2 * r + 1];
  } else {
    *p++ = kDigitPairs[2 * abs_sci];
    *p++ = kDigitPairs[2 * abs_sci + 1];
  }
  return p;
}

}  // namespace recruit::estimation
