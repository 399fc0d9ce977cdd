// Counts every heap allocation of a test program (operator new and Eigen's dynamic matrices
// alike), for tests that a step allocates nothing. glibc lets a program replace malloc; under the
// sanitizers (which own malloc) or another C library RECRUIT_COUNTS_MALLOC is not defined and
// such tests skip. Link malloc_counter.cc into the test program.
#pragma once

#include <cstddef>  // defines __GLIBC__ for the check below

#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(memory_sanitizer)
#define RECRUIT_SANITIZED_MALLOC 1
#endif
#endif
#if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__) && !defined(RECRUIT_SANITIZED_MALLOC)
#define RECRUIT_COUNTS_MALLOC 1
#endif

namespace recruit::testing {

// malloc, calloc and realloc calls so far (0 forever where RECRUIT_COUNTS_MALLOC is not defined).
long MallocCount();

}  // namespace recruit::testing
