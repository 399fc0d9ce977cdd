// Versions of this build: the CMake project version, and the code version that keys resumable
// results (project version + git commit at configure time). MuJoCo-free.
#pragma once

namespace recruit {

// The CMake project version, "major.minor.patch" (project(recruit VERSION ...)).
const char* ProjectVersion();  // version.cc
// "<project version>+<git commit>" (also declared in content_hash.h, for resume keys).
const char* CodeVersion();  // version.cc

}  // namespace recruit
