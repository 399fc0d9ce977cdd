// BM_GemmAvx: bench_estimation's BM_Gemm (C += A B, 256 x 256) compiled for AVX without FMA
// (-mavx): the flop rate of the instruction set the sparse step's AVX kernels use, the reference
// for their rate (docs/benchmarks.md). A program of its own, so that no Eigen code compiled for
// AVX is linked beside code compiled for the baseline. Needs a CPU with AVX.
#include <benchmark/benchmark.h>

#include <Eigen/Dense>
#include <random>

#if !defined(__AVX__) || defined(__FMA__)
#error "bench_gemm_avx is compiled with -mavx and without FMA"
#endif

namespace {

void BM_GemmAvx(benchmark::State& state) {
  const int n = 256;
  std::mt19937_64 gen(3);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  Eigen::MatrixXd A(n, n), B(n, n), C = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n * n; ++i) A.data()[i] = uniform(gen), B.data()[i] = uniform(gen);
  for (auto _ : state) {
    C.noalias() += A * B;
    benchmark::DoNotOptimize(C.data());
  }
  state.counters["GFLOPS"] =
      benchmark::Counter(2.0 * n * n * n * 1e-9 * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_GemmAvx);

}  // namespace
