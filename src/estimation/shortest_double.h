// Shortest round-trip formatting of doubles, several times faster than libstdc++'s
// std::to_chars and with the same characters: the digits are Dragonbox's (fmt), the layout is
// std::to_chars's (fixed or scientific, whichever is shorter, fixed on a tie; docs/formats/
// filter.md). For the CSV writers of large outputs (`recruit filter`).
#pragma once

namespace recruit::estimation {

// Longest output of WriteShortest ("-2.2250738585072014e-308").
inline constexpr int kShortestDoubleMaxChars = 24;
// Room WriteShortest needs at p: it stores whole 8-byte words, so it may write (unspecified
// characters) up to 8 places after the end it returns.
inline constexpr int kShortestDoubleRoom = 32;

// Writes v at p (at most kShortestDoubleMaxChars characters, no terminator; p must have
// kShortestDoubleRoom characters of room) and returns the end: exactly the characters of
// std::to_chars(p, p + 24, v) for every double, including zero, subnormals, infinities, NaN.
char* WriteShortest(char* p, double v);

}  // namespace recruit::estimation
