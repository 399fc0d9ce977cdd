// Content hash for resume keys: FNV-1a 64 over the bytes that determine a result (not a
// cryptographic hash: it detects edits, not adversaries), and the code version it is tied to.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

namespace recruit {

// Version of the code that made a result (common/version.h: project version, git commit, source
// hash). Results made by another version are not reused.
const char* CodeVersion();  // version.cc

class ContentHash {
 public:
  // Adds a length-prefixed field, so ("ab","c") and ("a","bc") differ.
  ContentHash& Add(std::string_view bytes) {
    const std::string len = std::to_string(bytes.size()) + ":";
    Mix(len);
    Mix(bytes);
    return *this;
  }
  std::string Hex() const {
    char buf[17];
    std::snprintf(buf, sizeof(buf), "%016llx", static_cast<unsigned long long>(h_));
    return buf;
  }

 private:
  void Mix(std::string_view bytes) {
    for (unsigned char c : bytes) {
      h_ ^= c;
      h_ *= 1099511628211ull;
    }
  }
  std::uint64_t h_ = 14695981039346656037ull;
};

}  // namespace recruit
