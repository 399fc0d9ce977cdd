#include "common/cpu_features.h"

#include <gtest/gtest.h>

namespace recruit {
namespace file_cpu_features_test {

// The C library's record of the CPU's features agrees with GCC's own CPUID-based check, feature
// by feature, on whatever CPU runs the test.
TEST(CpuFeatures, AgreeWithTheCompilersOwnCheck) {
#if defined(__x86_64__)
  __builtin_cpu_init();
  EXPECT_EQ(CpuRunsAvx(), __builtin_cpu_supports("avx") != 0);
  EXPECT_EQ(CpuRunsAvx2(), __builtin_cpu_supports("avx2") != 0);
  EXPECT_EQ(CpuRunsAvx512FDq(),
            __builtin_cpu_supports("avx512f") != 0 && __builtin_cpu_supports("avx512dq") != 0);
#else
  EXPECT_FALSE(CpuRunsAvx() || CpuRunsAvx2() || CpuRunsAvx512FDq());
#endif
}

}  // namespace file_cpu_features_test
}  // namespace recruit
