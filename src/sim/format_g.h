// FormatG: a double as printf("%.<precision>g") writes it (and fmt's "{:.<precision>g}"), byte
// for byte, at about a fifth of fmt's cost (bench/sim/format_g_bench.cc): the per-step CSV of
// `recruit simulate` formats ~6 new numbers per physics step.
#pragma once

#include <cstddef>

namespace recruit::sim {

// Longest text FormatG writes ("-1.2345678901234567e-308").
inline constexpr std::size_t kFormatGMax = 32;

// Writes `x` into `out` (room for kFormatGMax chars, which it may use as scratch past the text) as
// "%.<precision>g" (fast for precision 1..15, any other through fmt);
// returns the end of the text (not terminated).
char* FormatG(double x, int precision, char* out);

// A non-negative or negative integer in decimal; returns the end.
char* FormatInt(long x, char* out);

}  // namespace recruit::sim
