// Shortening of user-supplied values echoed in error messages: a 2 MB field must not come back
// whole in a message.
#pragma once

#include <cstdio>
#include <string>
#include <string_view>

namespace recruit {

// `s` if it has at most `max` characters, else its first `max` characters, "..." and the length.
// Control characters are shown as '?', so a message never carries terminal escapes.
inline std::string ShortText(std::string_view s, size_t max = 40) {
  std::string out;
  const size_t n = s.size() <= max ? s.size() : max;
  for (size_t i = 0; i < n; ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    out += (c < 0x20 || c == 0x7f) ? '?' : s[i];
  }
  if (s.size() > max) out += "... (" + std::to_string(s.size()) + " characters)";
  return out;
}

// Shortens every whitespace-separated token of `message` longer than `max` characters (for
// messages made by libraries, e.g. CLI11's "Could not convert: --dT = <value>").
inline std::string ShortenLongTokens(std::string_view message, size_t max = 40) {
  std::string out;
  size_t i = 0;
  while (i < message.size()) {
    if (message[i] == ' ' || message[i] == '\n' || message[i] == '\t') {
      out += message[i++];
      continue;
    }
    size_t j = i;
    while (j < message.size() && message[j] != ' ' && message[j] != '\n' && message[j] != '\t') ++j;
    out += ShortText(message.substr(i, j - i), max);
    i = j;
  }
  return out;
}

// `v` as printf's "%g" writes it (six significant digits): a number quoted in a message.
inline std::string GText(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace recruit
