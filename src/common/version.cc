// Compiled alone with RECRUIT_VERSION_STRING (src/common/CMakeLists.txt), so a new commit
// recompiles this file only.
#include "common/content_hash.h"

#ifndef RECRUIT_VERSION_STRING
#define RECRUIT_VERSION_STRING "unknown"
#endif

namespace recruit {
const char* CodeVersion() { return RECRUIT_VERSION_STRING; }
}  // namespace recruit
