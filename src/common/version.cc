// Compiled alone with RECRUIT_VERSION_STRING and the generated source hash
// (src/common/CMakeLists.txt), so a new commit or an edited source recompiles this file only.
#include "common/version.h"

#include <string>

#include "common/content_hash.h"

#ifndef RECRUIT_VERSION_STRING
#define RECRUIT_VERSION_STRING "unknown"
#endif
#include "source_hash.h"  // generated: RECRUIT_SOURCE_HASH

namespace recruit {
const char* CodeVersion() { return RECRUIT_VERSION_STRING "." RECRUIT_SOURCE_HASH; }

// RECRUIT_VERSION_STRING is "<project version>+<commit>": the part before '+'.
const char* ProjectVersion() {
  static const std::string version = [] {
    const std::string code = RECRUIT_VERSION_STRING;
    return code.substr(0, code.find('+'));
  }();
  return version.c_str();
}
}  // namespace recruit
