// Versions of this build: the CMake project version, and the code version that keys every result
// kept between processes (project version + git commit at configure time + a hash of the source
// files at build time, cmake/SourceHash.cmake). MuJoCo-free.
#pragma once

namespace recruit {

// The CMake project version, "major.minor.patch" (project(recruit VERSION ...)).
const char* ProjectVersion();  // version.cc
// "<project version>+<git commit>.<source hash>" (also declared in content_hash.h, for resume
// keys).
const char* CodeVersion();  // version.cc

}  // namespace recruit
