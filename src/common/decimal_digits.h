// Powers of ten and the decimal length of a 64-bit integer, shared by the number formatters
// (estimation/shortest_double.cc, sim/format_g.cc).
#pragma once

#include <cstdint>

namespace recruit {

inline constexpr std::uint64_t kPow10[20] = {1ull,
                                             10ull,
                                             100ull,
                                             1000ull,
                                             10000ull,
                                             100000ull,
                                             1000000ull,
                                             10000000ull,
                                             100000000ull,
                                             1000000000ull,
                                             10000000000ull,
                                             100000000000ull,
                                             1000000000000ull,
                                             10000000000000ull,
                                             100000000000000ull,
                                             1000000000000000ull,
                                             10000000000000000ull,
                                             100000000000000000ull,
                                             1000000000000000000ull,
                                             10000000000000000000ull};

// Decimal digits of v >= 1: t = floor(bits log10(2)) (1233 / 4096 ~ log10(2)) is the count or
// one less; one comparison decides.
inline int DecimalDigits(std::uint64_t v) {
  const int bits = 64 - __builtin_clzll(v);
  const int t = (bits * 1233) >> 12;
  return t + (v >= kPow10[t]);
}

}  // namespace recruit
