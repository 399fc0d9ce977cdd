// One exit code per class of failure, the same for every `recruit` command (docs/reliability.md).
#pragma once

#include <string>

namespace recruit::exit_code {

constexpr int kOk = 0;
constexpr int kUsage = 2;     // bad option or option value (CLI11 errors too), missing input path
constexpr int kBadInput = 3;  // an input file's content is invalid (task, model, log, MJCF, ...)
constexpr int kIo = 4;        // a file cannot be read or written (permissions, full disk, ...)
constexpr int kInternal = 5;  // a bug: an unexpected exception; please report it

// Classifies an error message of a Result/Status: I/O failures (the wording of AtomicFile,
// ReadFile, the JSON loader and the filesystem calls) are kIo, everything else is kBadInput.
inline int FromMessage(const std::string& message) {
  for (const char* marker :
       {"cannot open", "cannot write", "cannot read", "cannot rename", "cannot create", "disk full",
        "No space left", "File too large", "Permission denied", "Read-only file system"}) {
    if (message.find(marker) != std::string::npos) return kIo;
  }
  return kBadInput;
}

}  // namespace recruit::exit_code
