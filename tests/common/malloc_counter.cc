#include "malloc_counter.h"

#include <atomic>
#include <cstddef>

namespace {
std::atomic<long> g_mallocs{0};
}  // namespace

#ifdef RECRUIT_COUNTS_MALLOC
// Count, then forward to glibc's own allocator.
extern "C" {
void* __libc_malloc(size_t n);
void* __libc_calloc(size_t n, size_t size);
void* __libc_realloc(void* p, size_t n);
void __libc_free(void* p);
void* malloc(size_t n) {
  ++g_mallocs;
  return __libc_malloc(n);
}
void* calloc(size_t n, size_t size) {
  ++g_mallocs;
  return __libc_calloc(n, size);
}
void* realloc(void* p, size_t n) {
  ++g_mallocs;
  return __libc_realloc(p, n);
}
void free(void* p) { __libc_free(p); }
}
#endif

namespace recruit::testing {

long MallocCount() { return g_mallocs.load(); }

}  // namespace recruit::testing
