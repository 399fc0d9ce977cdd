#include "sil/transport.h"

#include <algorithm>

namespace recruit::sil {

void Refused::Count(ParseError e) {
  switch (e) {
    case ParseError::kNone:
      return;
    case ParseError::kTruncated:
      ++truncated;
      return;
    case ParseError::kOversized:
      ++oversized;
      return;
    default:
      ++malformed;
  }
}

int MillisecondsUntil(Clock::time_point deadline) {
  const auto ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return static_cast<int>(std::clamp<long long>(ms + 1, 0, 1 << 30));  // + 1: never early
}

}  // namespace recruit::sil
