// The vector instruction sets this process may use: the CPU has them and the operating system
// saves their registers. Read from what the C library found when the process started, so no
// CPUID of our own: in a virtual machine every CPUID traps to the hypervisor, and libgcc's
// __builtin_cpu_supports ran about ten of them at start-up in each library that used it.
#pragma once

#include <stdbool.h>  // before x86.h, so that its _Bool below is the one we define, if any

#if defined(__x86_64__) && defined(__has_include)
#if __has_include(<sys/platform/x86.h>)
// glibc 2.36's header declares its functions with C's _Bool, which clang's C++ does not know.
#if defined(__cplusplus) && !defined(_Bool)
#define _Bool bool
#define RECRUIT_UNDEF_BOOL 1
#endif
#include <sys/platform/x86.h>
#if defined(RECRUIT_UNDEF_BOOL)
#undef _Bool
#undef RECRUIT_UNDEF_BOOL
#endif
#if defined(CPU_FEATURE_ACTIVE)  // glibc >= 2.33; 2.32 has the header without it
#define RECRUIT_CPU_FROM_LIBC 1
#endif
#endif
#endif

namespace recruit {

// static: x86.h's functions are, so each file has its own copy of these too.

#if defined(RECRUIT_CPU_FROM_LIBC)
static inline bool CpuRunsAvx() { return CPU_FEATURE_ACTIVE(AVX); }
static inline bool CpuRunsAvx2() { return CPU_FEATURE_ACTIVE(AVX2); }
static inline bool CpuRunsAvx512FDq() {
  return CPU_FEATURE_ACTIVE(AVX512F) && CPU_FEATURE_ACTIVE(AVX512DQ);
}
#elif defined(__x86_64__)
static inline bool CpuRunsAvx() { return __builtin_cpu_init(), __builtin_cpu_supports("avx") != 0; }
static inline bool CpuRunsAvx2() {
  return __builtin_cpu_init(), __builtin_cpu_supports("avx2") != 0;
}
static inline bool CpuRunsAvx512FDq() {
  return __builtin_cpu_init(),
         __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq");
}
#else
static inline bool CpuRunsAvx() { return false; }
static inline bool CpuRunsAvx2() { return false; }
static inline bool CpuRunsAvx512FDq() { return false; }
#endif

}  // namespace recruit
