// Compiled alone with RECRUIT_VERSION_STRING (src/common/CMakeLists.txt), so a new commit
// recompiles this file only.
#include "common/version.h"

#include <string>

#include "common/content_hash.h"

#ifndef RECRUIT_VERSION_STRING
#define RECRUIT_VERSION_STRING "unknown"
#endif

namespace recruit {
const char* CodeVersion() { return RECRUIT_VERSION_STRING; }

// RECRUIT_VERSION_STRING is "<project version>+<commit>": the part before '+'.
const char* ProjectVersion() {
  static const std::string version = [] {
    const std::string code = RECRUIT_VERSION_STRING;
    return code.substr(0, code.find('+'));
  }();
  return version.c_str();
}
}  // namespace recruit
