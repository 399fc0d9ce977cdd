// One exit code per class of failure, the same for every `recruit` command (docs/reliability.md).
// The class travels with the error (ErrorCode, common/result.h), never in its wording.
#pragma once

#include "common/result.h"

namespace recruit::exit_code {

constexpr int kOk = 0;
constexpr int kUsage = 2;     // bad option or option value (CLI11 errors too), missing input path
constexpr int kBadInput = 3;  // an input file's content is invalid (task, model, log, MJCF, ...)
constexpr int kIo = 4;        // a file cannot be read or written (permissions, full disk, ...)
constexpr int kInternal = 5;  // a bug: an unexpected exception; please report it
constexpr int kNoController = 6;  // recruit sil: the controller never connected, or fell silent

inline int Of(ErrorCode code) {
  switch (code) {
    case ErrorCode::kBadInput:
      return kBadInput;
    case ErrorCode::kUsage:
      return kUsage;
    case ErrorCode::kIo:
      return kIo;
    case ErrorCode::kInternal:
      return kInternal;
  }
  return kInternal;
}
inline int Of(const Error& e) { return Of(e.code); }

}  // namespace recruit::exit_code
