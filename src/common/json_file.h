// A safe JSON loader for every input file (task, sweep records, models): a size limit, a nesting
// depth limit checked before parsing (a 70,000-deep file must not exhaust the stack), numbers
// too large for a double reported as such (nlohmann throws out_of_range for them, not a parse
// error), a UTF-8 byte-order mark skipped, and messages that name the file and shorten values.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

#include "common/result.h"

namespace recruit {

struct JsonLimits {
  std::size_t max_bytes = std::size_t{64} << 20;  // 64 MiB
  int max_depth = 128;                            // nested arrays / objects
};

// Parses `text`; `source` names the file in errors ("<text>" if empty).
Result<nlohmann::json> ParseJsonText(const std::string& text, const std::string& source,
                                     const JsonLimits& limits = {});

// Reads and parses `path` (errors name the file; one that is not there is bad input, one that
// cannot be read I/O: CodeOf, common/result.h).
Result<nlohmann::json> LoadJsonFile(const std::string& path, const JsonLimits& limits = {});

// Deepest nesting of arrays / objects in `text` (strings skipped), stopping early once it
// exceeds `stop_above`.
int JsonNestingDepth(const std::string& text, int stop_above);

}  // namespace recruit
