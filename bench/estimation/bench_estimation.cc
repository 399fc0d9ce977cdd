// Estimation benchmarks (docs/benchmarks.md, "Estimation (issue 2)"):
//  - BM_KalmanStep<M>: one predict + update of the fixed-size extended filter, r = 1, against
//    its floating-point operation count (counter "flops" per step and "GFLOPS" achieved);
//    BM_KalmanStepLegacy<M>: the same with the filter of commit f33d0b3 (legacy_kalman_filter.h),
//    the side-by-side baseline of this run;
//  - BM_BroadcastStep/<path>: one predict + update of PopulationKalmanFilterT<20, 1> with the
//    identified 20-state broadcast model (models/identified/bench_n60_dt0.5_m20.json), A built
//    from (p_on, p_off) inside the timed step: path 0 = legacy dense, 1 = dense, 2 = sparse A;
//    BM_KalmanStepDynamic: the same with dynamic-size matrices;
//  - BM_Gemm: a 256 x 256 dense matrix product, the machine's achievable flop rate with the
//    same compiler flags (the reference for the flop bound; bench_gemm_avx.cc is the same for
//    AVX without FMA, the reference of the sparse step's AVX kernels);
//  - BM_ChainStep<M>/<path>: the heating / cooling chain, dense A, sparse A with the kernels
//    the filter picks (AVX where the CPU has it), sparse A with the baseline kernels;
//  - BM_ParseFilterModel/<path>: reading an identified model's JSON text (16 KB, what
//    `recruit simulate` does for each bundle at start-up): 0 = ParseJsonText (common/json_file.h:
//    a depth pre-scan, then the parse), 1 = nlohmann::json::parse alone, the reference;
//  - BM_Estimator/<kind>/m: time per step of the extended Kalman filter, the exact filter
//    (every step a new A, and a constant, cached A) and a particle filter with the smallest
//    particle count whose RMSE is within 5 % of the Kalman filter's (found by a calibration
//    run at start-up, reported as counters).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include "common/json_file.h"
#include "common/rng.h"
#include "estimation/exact_filter.h"
#include "estimation/particle_filter.h"
#include "estimation/population_chain.h"
#include "estimation/population_kalman_filter.h"
#include "legacy_kalman_filter.h"

namespace recruit {
namespace {

constexpr int kSequence = 64;

double Gaussian(Rng& rng) {
  const double u1 = 1.0 - rng.Uniform(), u2 = rng.Uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

// A chain of m states: a birth-death-like random column-stochastic A with all entries > 0, a
// force sensor H (state i gives 0.45 i / (m - 1) N per unit), N = 60 units.
estimation::FilterModel ChainModel(int m, double noise_std = 0.6) {
  estimation::FilterModel f;
  for (int i = 0; i < m; ++i) f.state_names.push_back("s" + std::to_string(i));
  f.N = 60;
  f.H.resize(1, m);
  for (int i = 0; i < m; ++i) f.H(0, i) = m == 1 ? 0.45 : 0.45 * i / (m - 1);
  f.R = Eigen::MatrixXd::Constant(1, 1, noise_std * noise_std);
  f.G = Eigen::MatrixXd::Zero(m, 0);
  f.Qw = Eigen::MatrixXd::Zero(0, 0);
  f.transition = estimation::TransitionSource::kExplicit;
  f.x0 = Eigen::VectorXd::Zero(m);
  f.x0(0) = 60;
  f.P0 = Eigen::MatrixXd::Zero(m, m);
  return f;
}

Eigen::MatrixXd RandomStochastic(int m, Rng& rng) {
  Eigen::MatrixXd A(m, m);
  for (int j = 0; j < m; ++j) {
    for (int i = 0; i < m; ++i) A(i, j) = 0.02 + rng.Uniform() * (i == j ? 4.0 : 1.0);
    A.col(j) /= A.col(j).sum();
  }
  return A;
}

// Simulated inputs and measurements of one run of the chain.
struct Sequence {
  std::vector<Eigen::MatrixXd> A;
  std::vector<Eigen::VectorXd> y, x;
};

Sequence Simulate(const estimation::FilterModel& f, int steps, uint64_t seed,
                  bool distinct_A = true) {
  Rng rng(seed);
  Sequence s;
  Eigen::VectorXd x = f.x0;
  const Eigen::MatrixXd A0 = RandomStochastic(f.num_states(), rng);
  for (int t = 0; t < steps; ++t) {
    s.x.push_back(x);
    s.y.push_back(f.H * x + Eigen::VectorXd::Constant(1, std::sqrt(f.R(0, 0)) * Gaussian(rng)));
    s.A.push_back(distinct_A ? RandomStochastic(f.num_states(), rng) : A0);
    x = estimation::SimulateStepAggregate(s.A.back(), x, rng);
  }
  return s;
}

// Floating-point operations of one extended step (r = 1) with a dense A, as implemented:
// predict 2 m^3 (A M) + m^3 (upper triangle of (A M) A^T; the full 2 m^3 for m < 16)
// + 4 m^2 (A x, A xq) + 3 m^2 (reprojection), update 4 m^2 (P h^T, P - w w^T) + O(m).
double StepFlops(int m) { return (m < 16 ? 4.0 : 3.0) * m * m * m + 11.0 * m * m + 10.0 * m; }

// The same with a sparse A (PopulationKalmanFilterT::PredictRows, PredictBroadcast): first
// pass 2 m nnz (B = (P - diag xq) A^T) + 2 nnz (A x; A xq = A x for a feasible x), second pass
// 2 len(i) per nonzero A(i, l) with len(i) = rows 0..i rounded up to whole SIMD packets (upper
// triangle of A B), update 4 m^2 + O(m), the projection onto 1^T P = 0 (3 m^2) every 16th step.
double SparseStepFlops(const Eigen::SparseMatrix<double>& A) {
  const double m = static_cast<double>(A.rows());
  const int round = std::max(2, estimation::kf_detail::kPacket);
  double second = 0.0;
  for (int l = 0; l < A.outerSize(); ++l) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, l); it; ++it) {
      const int len = (static_cast<int>(it.row()) + round) / round * round;
      second += 2.0 * std::min<double>(m, len);
    }
  }
  const double nnz = static_cast<double>(A.nonZeros());
  return 2.0 * m * nnz + 2.0 * nnz + second + 4.0 * m * m + 3.0 * m * m / 16.0 + 10.0 * m;
}

template <int M>
void BM_KalmanStep(benchmark::State& state) {
  const estimation::FilterModel f = ChainModel(M);
  const Sequence s = Simulate(f, kSequence, 1);
  std::vector<Eigen::Matrix<double, M, M>> A(s.A.begin(), s.A.end());
  std::vector<Eigen::Matrix<double, 1, 1>> y;
  for (const auto& v : s.y) y.emplace_back(v(0));
  auto kf =
      estimation::PopulationKalmanFilterT<M, 1>::Create(f, estimation::CovarianceMode::kExtended);
  int t = 0;
  for (auto _ : state) {
    kf->Predict(A[t]);
    kf->Update(y[t]);
    benchmark::DoNotOptimize(kf->estimate().data());
    t = (t + 1) % kSequence;
  }
  state.counters["flops"] = StepFlops(M);
  state.counters["GFLOPS"] =
      benchmark::Counter(StepFlops(M) * 1e-9 * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK_TEMPLATE(BM_KalmanStep, 2);
BENCHMARK_TEMPLATE(BM_KalmanStep, 3);
BENCHMARK_TEMPLATE(BM_KalmanStep, 5);
BENCHMARK_TEMPLATE(BM_KalmanStep, 10);
BENCHMARK_TEMPLATE(BM_KalmanStep, 20);
BENCHMARK_TEMPLATE(BM_KalmanStep, 50);

template <int M>
void BM_KalmanStepLegacy(benchmark::State& state) {
  const estimation::FilterModel f = ChainModel(M);
  const Sequence s = Simulate(f, kSequence, 1);
  std::vector<Eigen::Matrix<double, M, M>> A(s.A.begin(), s.A.end());
  std::vector<Eigen::Matrix<double, 1, 1>> y;
  for (const auto& v : s.y) y.emplace_back(v(0));
  auto kf = legacy::LegacyKalmanFilterT<M, 1>::Create(f, estimation::CovarianceMode::kExtended);
  int t = 0;
  for (auto _ : state) {
    kf->Predict(A[t]);
    kf->Update(y[t]);
    benchmark::DoNotOptimize(kf->estimate().data());
    t = (t + 1) % kSequence;
  }
  state.counters["flops"] = StepFlops(M);
}
BENCHMARK_TEMPLATE(BM_KalmanStepLegacy, 2);
BENCHMARK_TEMPLATE(BM_KalmanStepLegacy, 3);
BENCHMARK_TEMPLATE(BM_KalmanStepLegacy, 5);
BENCHMARK_TEMPLATE(BM_KalmanStepLegacy, 10);
BENCHMARK_TEMPLATE(BM_KalmanStepLegacy, 20);
BENCHMARK_TEMPLATE(BM_KalmanStepLegacy, 50);

// The identified 20-state broadcast model, stepped with random (p_on, p_off) and force
// measurements of a simulated run; range(0): 0 = legacy dense, 1 = dense, 2 = sparse A.
void BM_BroadcastStep(benchmark::State& state) {
  constexpr int kM = 20;
  auto model = estimation::FilterModel::FromJson(RECRUIT_SOURCE_DIR
                                                 "/models/identified/bench_n60_dt0.5_m20.json");
  if (!model.ok()) {
    state.SkipWithError(model.error().c_str());
    return;
  }
  const estimation::FilterModel& f = *model;
  const estimation::BroadcastTransitionModel& b = f.broadcast;
  Rng rng(7);
  std::vector<double> p_on(kSequence), p_off(kSequence);
  std::vector<Eigen::Matrix<double, 1, 1>> y(kSequence);
  Eigen::VectorXd x = f.x0;
  for (int t = 0; t < kSequence; ++t) {
    p_on[t] = rng.Uniform();
    p_off[t] = rng.Uniform();
    y[t] = f.H * x + Eigen::VectorXd::Constant(1, std::sqrt(f.R(0, 0)) * Gaussian(rng));
    x = estimation::SimulateStepAggregate(b.Matrix(p_on[t], p_off[t]), x, rng);
  }
  const int path = static_cast<int>(state.range(0));
  auto kf =
      estimation::PopulationKalmanFilterT<kM, 1>::Create(f, estimation::CovarianceMode::kExtended);
  auto old = legacy::LegacyKalmanFilterT<kM, 1>::Create(f, estimation::CovarianceMode::kExtended);
  Eigen::Matrix<double, kM, kM> A;
  Eigen::SparseMatrix<double> As = b.SparsePattern();
  int t = 0;
  for (auto _ : state) {
    if (path == 0) {
      b.FillMatrix(p_on[t], p_off[t], A);
      old->Predict(A);
      old->Update(y[t]);
      benchmark::DoNotOptimize(old->estimate().data());
    } else if (path == 1) {
      b.FillMatrix(p_on[t], p_off[t], A);
      kf->Predict(A);
      kf->Update(y[t]);
      benchmark::DoNotOptimize(kf->estimate().data());
    } else {
      b.FillSparse(p_on[t], p_off[t], As);
      kf->Predict(As);
      kf->Update(y[t]);
      benchmark::DoNotOptimize(kf->estimate().data());
    }
    t = (t + 1) % kSequence;
  }
  state.counters["nnz_A"] = static_cast<double>(As.nonZeros());
}
BENCHMARK(BM_BroadcastStep)->Arg(0)->Arg(1)->Arg(2);

// The m-state heating / cooling chain (BroadcastTransitionModel::HeatingChain, at most 3
// nonzeros per column of A), N = 60, a force sensor, random (p_on, p_off) in [0, 0.3] and the
// measurements of a simulated run. range(0): 0 = dense A (FillMatrix + Predict(Mat), the
// reference of this run), 1 = sparse A (PredictBroadcast: FillSparse in place + sparse
// predict) with the kernels the filter chooses (the AVX copy where the CPU has it, counter
// avx = 1), 2 = the same with the baseline kernels forced. Counters: flops per step of the
// algorithm the path runs (for paths 1 and 2 the same count, that of the baseline kernels, so
// that their rates compare as their times), GFLOPS achieved.
template <int M>
void BM_ChainStep(benchmark::State& state) {
  estimation::FilterModel f = ChainModel(M);
  f.transition = estimation::TransitionSource::kBroadcast;
  f.broadcast = estimation::BroadcastTransitionModel::HeatingChain(M, 0.5);
  f.state_names = f.broadcast.state_names;
  for (int i = 0; i < M; ++i) {
    const int h = M / 2;
    f.H(0, i) = i == 0 ? 0.0 : i <= h ? 0.45 * i / h : 0.45 * (1.0 - double(i - h) / (M - h));
  }
  const estimation::BroadcastTransitionModel& b = f.broadcast;
  Rng rng(7);
  std::vector<double> p_on(kSequence), p_off(kSequence);
  std::vector<Eigen::Matrix<double, 1, 1>> y(kSequence);
  Eigen::VectorXd x = f.x0;
  for (int t = 0; t < kSequence; ++t) {
    p_on[t] = 0.3 * rng.Uniform();
    p_off[t] = 0.3 * rng.Uniform();
    y[t] = f.H * x + Eigen::VectorXd::Constant(1, std::sqrt(f.R(0, 0)) * Gaussian(rng));
    x = estimation::SimulateStepAggregate(b.Matrix(p_on[t], p_off[t]), x, rng);
  }
  const bool sparse = state.range(0) >= 1;
  auto kf =
      estimation::PopulationKalmanFilterT<M, 1>::Create(f, estimation::CovarianceMode::kExtended);
  if (!kf.ok()) {
    state.SkipWithError(kf.error().c_str());
    return;
  }
  if (state.range(0) == 2) kf->set_avx_kernels(false);
  Eigen::Matrix<double, M, M> A;
  int t = 0;
  for (auto _ : state) {
    if (sparse) {
      kf->PredictBroadcast(p_on[t], p_off[t]);
    } else {
      b.FillMatrix(p_on[t], p_off[t], A);
      kf->Predict(A);
    }
    kf->Update(y[t]);
    benchmark::DoNotOptimize(kf->estimate().data());
    t = (t + 1) % kSequence;
  }
  const double flops = sparse ? SparseStepFlops(kf->broadcast_matrix()) : StepFlops(M);
  state.counters["nnz_A"] = static_cast<double>(kf->broadcast_matrix().nonZeros());
  state.counters["avx"] = sparse && kf->avx_kernels() ? 1.0 : 0.0;  // the dense path has none
  state.counters["flops"] = flops;
  state.counters["GFLOPS"] =
      benchmark::Counter(flops * 1e-9 * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK_TEMPLATE(BM_ChainStep, 20)->Arg(0)->Arg(1)->Arg(2);
BENCHMARK_TEMPLATE(BM_ChainStep, 50)->Arg(0)->Arg(1)->Arg(2);

void BM_KalmanStepDynamic(benchmark::State& state) {
  const int m = static_cast<int>(state.range(0));
  const estimation::FilterModel f = ChainModel(m);
  const Sequence s = Simulate(f, kSequence, 1);
  auto kf = estimation::PopulationKalmanFilter::Create(f, estimation::CovarianceMode::kExtended);
  int t = 0;
  for (auto _ : state) {
    kf->Predict(s.A[t]);
    kf->Update(s.y[t]);
    benchmark::DoNotOptimize(kf->estimate().data());
    t = (t + 1) % kSequence;
  }
  state.counters["flops"] = StepFlops(m);
  state.counters["GFLOPS"] =
      benchmark::Counter(StepFlops(m) * 1e-9 * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_KalmanStepDynamic)->Arg(2)->Arg(5)->Arg(10)->Arg(20)->Arg(50);

// The same with the filter of commit f33d0b3 (side-by-side baseline).
void BM_KalmanStepDynamicLegacy(benchmark::State& state) {
  const int m = static_cast<int>(state.range(0));
  const estimation::FilterModel f = ChainModel(m);
  const Sequence s = Simulate(f, kSequence, 1);
  auto kf = legacy::LegacyKalmanFilterT<Eigen::Dynamic, Eigen::Dynamic>::Create(
      f, estimation::CovarianceMode::kExtended);
  int t = 0;
  for (auto _ : state) {
    kf->Predict(s.A[t]);
    kf->Update(s.y[t]);
    benchmark::DoNotOptimize(kf->estimate().data());
    t = (t + 1) % kSequence;
  }
}
BENCHMARK(BM_KalmanStepDynamicLegacy)->Arg(2)->Arg(5)->Arg(10)->Arg(20)->Arg(50);

// The achievable flop rate: C += A B, 256 x 256, 2 n^3 flops.
void BM_Gemm(benchmark::State& state) {
  const int n = 256;
  Rng rng(3);
  Eigen::MatrixXd A(n, n), B(n, n), C = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n * n; ++i) A.data()[i] = rng.Uniform(), B.data()[i] = rng.Uniform();
  for (auto _ : state) {
    C.noalias() += A * B;
    benchmark::DoNotOptimize(C.data());
  }
  state.counters["GFLOPS"] =
      benchmark::Counter(2.0 * n * n * n * 1e-9 * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Gemm);

// RMSE over `runs` simulated runs of `steps` steps (same runs for every estimator).
template <class Step>
double Rmse(const estimation::FilterModel& f, int runs, int steps, Step step) {
  double se = 0;
  for (int r = 0; r < runs; ++r) {
    const Sequence s = Simulate(f, steps, 100 + r);
    se += step(s, r);
  }
  return std::sqrt(se / (static_cast<double>(runs) * steps));
}

double KalmanSquaredErrors(const estimation::FilterModel& f, const Sequence& s) {
  auto kf = estimation::PopulationKalmanFilter::Create(f, estimation::CovarianceMode::kExtended);
  double se = 0;
  for (size_t t = 0; t < s.y.size(); ++t) {
    if (t > 0) kf->Predict(s.A[t - 1]);
    kf->Update(s.y[t]);
    se += (kf->estimate() - s.x[t]).squaredNorm();
  }
  return se;
}

double ParticleSquaredErrors(const estimation::FilterModel& f, const Sequence& s, int particles,
                             int run) {
  Rng rng(Rng::DeriveSeed(55, run));
  auto pf = estimation::ParticleFilter::Create(f, {particles, 0.5}, rng);
  double se = 0;
  for (size_t t = 0; t < s.y.size(); ++t) {
    if (t > 0) pf->Predict(s.A[t - 1], rng);
    pf->Update(s.y[t], rng);
    se += (pf->Mean() - s.x[t]).squaredNorm();
  }
  return se;
}

// The smallest particle count (doubling from 16) whose RMSE over 200 runs x 30 steps (50 runs
// for m > 3) is within 5 % of the extended Kalman filter's on the same runs.
struct Calibration {
  int particles = 0;
  double rmse_kalman = 0, rmse_particle = 0;
};

const Calibration& Calibrate(int m, double noise_std) {
  static std::map<std::pair<int, double>, Calibration> cache;
  auto it = cache.find({m, noise_std});
  if (it != cache.end()) return it->second;
  const estimation::FilterModel f = ChainModel(m, noise_std);
  const int runs = m <= 3 ? 200 : 50;
  Calibration c;
  c.rmse_kalman =
      Rmse(f, runs, 30, [&](const Sequence& s, int) { return KalmanSquaredErrors(f, s); });
  for (int np = 16; np <= 65536; np *= 2) {
    c.particles = np;
    c.rmse_particle = Rmse(
        f, 200, 30, [&](const Sequence& s, int r) { return ParticleSquaredErrors(f, s, np, r); });
    if (c.rmse_particle <= 1.05 * c.rmse_kalman) break;
  }
  return cache[{m, noise_std}] = c;
}

// range(0) = m, range(1) = force noise standard deviation in mN (600: 0.6 N, 1.3 units of
// 0.45 N; 100: 0.1 N, a sharp sensor that makes the particle filter degenerate).
void BM_EstimatorKalman(benchmark::State& state) {
  const int m = static_cast<int>(state.range(0));
  const estimation::FilterModel f = ChainModel(m, state.range(1) * 1e-3);
  const Sequence s = Simulate(f, kSequence, 1);
  auto kf = estimation::PopulationKalmanFilter::Create(f, estimation::CovarianceMode::kExtended);
  int t = 0;
  for (auto _ : state) {
    kf->Predict(s.A[t]);
    kf->Update(s.y[t]);
    benchmark::DoNotOptimize(kf->estimate().data());
    t = (t + 1) % kSequence;
  }
}
BENCHMARK(BM_EstimatorKalman)
    ->Args({2, 600})
    ->Args({3, 600})
    ->Args({10, 600})
    ->Args({2, 100})
    ->Args({3, 100});

// Exact filter; range(1) = 1: a new A every step (the transition table is rebuilt: the
// closed-loop case), 0: one constant A (the cached table, a dense S x S matrix-vector product).
void BM_EstimatorExact(benchmark::State& state) {
  const int m = static_cast<int>(state.range(0));
  const bool distinct = state.range(1) == 1;
  const estimation::FilterModel f = ChainModel(m);
  const Sequence s = Simulate(f, kSequence, 1, distinct);
  estimation::ExactFilterOptions o;
  if (distinct) o.cache_bytes = 0;
  auto ex = estimation::ExactBayesFilter::Create(f, o);
  ex->Predict(s.A[0]);  // outside the timing: builds the cached table for the constant A
  ex->Update(s.y[0]);
  int t = 0;
  for (auto _ : state) {
    ex->Predict(s.A[t]);
    ex->Update(s.y[t]);
    benchmark::DoNotOptimize(ex->probabilities().data());
    t = (t + 1) % kSequence;
  }
  state.counters["count_vectors"] = static_cast<double>(ex->num_count_vectors());
}
BENCHMARK(BM_EstimatorExact)
    ->Args({2, 1})
    ->Args({2, 0})
    ->Args({3, 1})
    ->Args({3, 0})
    ->Unit(benchmark::kMicrosecond);

void BM_EstimatorParticle(benchmark::State& state) {
  const int m = static_cast<int>(state.range(0));
  const double noise = state.range(1) * 1e-3;
  const Calibration& c = Calibrate(m, noise);
  const estimation::FilterModel f = ChainModel(m, noise);
  const Sequence s = Simulate(f, kSequence, 1);
  Rng rng(9);
  auto pf = estimation::ParticleFilter::Create(f, {c.particles, 0.5}, rng);
  int t = 0;
  for (auto _ : state) {
    pf->Predict(s.A[t], rng);
    pf->Update(s.y[t], rng);
    benchmark::DoNotOptimize(pf->Mean().data());
    t = (t + 1) % kSequence;
  }
  state.counters["particles"] = c.particles;
  state.counters["rmse_ratio_to_kalman"] = c.rmse_particle / c.rmse_kalman;
}
BENCHMARK(BM_EstimatorParticle)
    ->Args({2, 600})
    ->Args({3, 600})
    ->Args({10, 600})
    ->Args({2, 100})
    ->Args({3, 100})
    ->Unit(benchmark::kMicrosecond);

void BM_ParseFilterModel(benchmark::State& state) {
  std::ifstream in(RECRUIT_SOURCE_DIR "/models/identified/flexor_104229eb693169de_dt1_m20.json");
  std::stringstream text;
  text << in.rdbuf();
  const std::string json = text.str();
  for (auto _ : state) {
    if (state.range(0) == 0) {
      auto j = ParseJsonText(json, "model.json");
      benchmark::DoNotOptimize(j);
    } else {
      auto j = nlohmann::json::parse(json);
      benchmark::DoNotOptimize(j);
    }
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * json.size()));
}
BENCHMARK(BM_ParseFilterModel)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace recruit
