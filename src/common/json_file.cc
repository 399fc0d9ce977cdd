#include "common/json_file.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>

#include "common/atomic_file.h"
#include "common/short_text.h"

namespace recruit {

int JsonNestingDepth(const std::string& text, int stop_above) {
  int depth = 0, deepest = 0;
  bool in_string = false, escaped = false;
  for (char c : text) {
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > deepest) deepest = depth;
      if (deepest > stop_above) return deepest;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}

Result<nlohmann::json> ParseJsonText(const std::string& text, const std::string& source,
                                     const JsonLimits& limits) {
  const std::string file = source.empty() ? std::string("<text>") : source;
  if (text.size() > limits.max_bytes) {
    return Error{file + ": " + std::to_string(text.size()) + " bytes; at most " +
                 std::to_string(limits.max_bytes) + " allowed"};
  }
  // A UTF-8 byte-order mark (editors on Windows add one) is not JSON but harmless.
  const std::size_t start = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
  if (JsonNestingDepth(text, limits.max_depth) > limits.max_depth) {
    return Error{file + ": arrays/objects nested more than " + std::to_string(limits.max_depth) +
                 " deep; not allowed"};
  }
  try {
    return nlohmann::json::parse(text.begin() + static_cast<std::ptrdiff_t>(start), text.end());
  } catch (const nlohmann::json::out_of_range& e) {
    // 406: a number that does not fit a double (1e999).
    return Error{file + ": a number is too large for a double (allowed: |x| < 1.8e308): " +
                 ShortenLongTokens(e.what())};
  } catch (const nlohmann::json::exception& e) {
    return Error{file + ": not valid JSON: " + ShortenLongTokens(e.what())};
  }
}

Result<nlohmann::json> LoadJsonFile(const std::string& path, const JsonLimits& limits) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    const int err = errno;
    return Error{"cannot read '" + ShortText(path, 200) + "': " + std::strerror(err),
                 CodeOfErrno(err)};
  }
  if (S_ISREG(st.st_mode) && static_cast<std::size_t>(st.st_size) > limits.max_bytes) {
    return Error{path + ": " + std::to_string(st.st_size) + " bytes; at most " +
                 std::to_string(limits.max_bytes) + " allowed"};
  }
  auto text = ReadFile(path);
  if (!text.ok()) return text.failure();
  return ParseJsonText(*text, path, limits);
}

}  // namespace recruit
