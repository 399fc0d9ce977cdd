// The filter's steps do not touch the heap: global operator new is replaced in this test
// program by a counting one, and (glibc, no sanitizer) so is malloc, which also sees Eigen's
// dynamic-size matrices (they allocate with malloc, not operator new).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <vector>

#include "estimation/count_filter.h"
#include "estimation/population_kalman_filter.h"
#include "test_util.h"
#include "tests/common/malloc_counter.h"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace recruit {
namespace {

template <int M>
long AllocationsPerSteps(estimation::CovarianceMode mode) {
  estimation::FilterModel f;
  for (int i = 0; i < M; ++i) f.state_names.push_back("s" + std::to_string(i));
  f.N = 60;
  f.H = Eigen::MatrixXd::Constant(1, M, 0.1);
  f.H(0, M - 1) = 0.45;
  f.R = Eigen::MatrixXd::Constant(1, 1, 0.3);
  f.G = Eigen::MatrixXd::Zero(M, 0);
  f.Qw = Eigen::MatrixXd::Zero(0, 0);
  f.transition = estimation::TransitionSource::kExplicit;
  f.x0 = Eigen::VectorXd::Zero(M);
  f.x0(0) = 60;
  f.P0 = Eigen::MatrixXd::Zero(M, M);
  auto kf = estimation::PopulationKalmanFilterT<M, 1>::Create(f, mode);
  EXPECT_TRUE(kf.ok());
  Eigen::Matrix<double, M, M> A = Eigen::Matrix<double, M, M>::Constant(0.5 / M);
  A.diagonal().array() += 0.5;
  const Eigen::Matrix<double, 1, 1> y(5.0);
  const long before = g_allocations.load();
  for (int t = 0; t < 100; ++t) {
    kf->Predict(A);
    if (t % 2) kf->Update(y);
  }
  return g_allocations.load() - before;
}

// The sparse-A Predict with a broadcast model's pattern built once (outside the count):
// FillSparse and Predict write in place.
long AllocationsPerSparseSteps() {
  constexpr int M = 3;
  const estimation::FilterModel f = testing_util::ThreeStateModel(60, std::sqrt(0.3));
  const estimation::BroadcastTransitionModel& b = f.broadcast;
  auto kf =
      estimation::PopulationKalmanFilterT<M, 1>::Create(f, estimation::CovarianceMode::kExtended);
  EXPECT_TRUE(kf.ok());
  Eigen::SparseMatrix<double> A = b.SparsePattern();
  const Eigen::Matrix<double, 1, 1> y(5.0);
  const long before = g_allocations.load();
  for (int t = 0; t < 100; ++t) {
    b.FillSparse(0.01 * t, 0.005 * t, A);
    kf->Predict(A);
    kf->Update(y);
  }
  return g_allocations.load() - before;
}

// PredictBroadcast (the filter's own sparse A, filled in place) and the scalar update, with the
// m = 20 heating / cooling chain.
// The m-state heating / cooling chain with a force sensor (at most 3 nonzeros per column of A).
estimation::FilterModel ChainModel(int m) {
  estimation::FilterModel f = testing_util::ThreeStateModel(60, std::sqrt(0.3));
  f.broadcast = estimation::BroadcastTransitionModel::HeatingChain(m, 0.5);
  f.state_names = f.broadcast.state_names;
  f.H = Eigen::MatrixXd::Constant(1, m, 0.2);
  f.H(0, 0) = 0.0;
  f.G = Eigen::MatrixXd::Zero(m, 0);
  f.x0 = Eigen::VectorXd::Zero(m);
  f.x0(0) = 60;
  f.P0 = Eigen::MatrixXd::Zero(m, m);
  return f;
}

long AllocationsPerBroadcastSteps() {
  constexpr int M = 20;
  const estimation::FilterModel f = ChainModel(M);
  auto kf =
      estimation::PopulationKalmanFilterT<M, 1>::Create(f, estimation::CovarianceMode::kExtended);
  EXPECT_TRUE(kf.ok()) << kf.error();
  if (!kf.ok()) return -1;
  const Eigen::Matrix<double, 1, 1> y(5.0);
  const long before = g_allocations.load();
  for (int t = 0; t < 100; ++t) {
    kf->PredictBroadcast(0.002 * t, 0.001 * t);
    kf->Update(y);
  }
  return g_allocations.load() - before;
}

// No dynamic-size matrix in the numeric state: (X^, P) and the workspaces live in the object
// (the broadcast pattern of PredictBroadcast is built once at Create and written in place).
static_assert(estimation::PopulationKalmanFilterT<20, 1>::Mat::RowsAtCompileTime == 20);
static_assert(sizeof(estimation::PopulationKalmanFilterT<20, 1>) >= 4 * 20 * 20 * sizeof(double));

// malloc calls in 100 steps of the controller's sequence on the dynamic-size filter
// (src/control/kalman_estimator.cc: SetOutput with an H that changes every step, Update,
// PredictBroadcast), after one warm-up step. Large p_off drives counts below zero at times, so
// the simplex projection runs too. (Unused where malloc cannot be counted: sanitizers.)
[[maybe_unused]] long MallocsPerDynamicSteps(int m, estimation::CovarianceMode mode) {
  const estimation::FilterModel f = ChainModel(m);
  auto kf = estimation::PopulationKalmanFilter::Create(f, mode);
  EXPECT_TRUE(kf.ok()) << kf.error();
  if (!kf.ok()) return -1;
  Eigen::MatrixXd h = f.H, r = f.R;
  Eigen::VectorXd y(1);
  long before = 0;
  for (int t = 0; t <= 100; ++t) {
    if (t == 1) before = testing::MallocCount();
    h(0, m - 1) = 0.1 + 0.001 * t;
    kf->SetOutput(h, r);
    y(0) = 5.0 + 0.1 * (t % 7);
    kf->Update(y);
    kf->PredictBroadcast(0.003 * t, 0.009 * t);
  }
  return testing::MallocCount() - before;
}

// The same through MakeCountFilter's Kalman adapter (what `recruit filter` runs: fixed size for
// m = 20, dynamic for m = 50), with MeanAndVariance as the streamed output reads it.
[[maybe_unused]] long MallocsPerCountFilterSteps(int m) {
  const estimation::FilterModel f = ChainModel(m);
  auto cf = estimation::MakeCountFilter(f, estimation::CountFilterOptions{});
  EXPECT_TRUE(cf.ok()) << cf.error();
  if (!cf.ok()) return -1;
  Eigen::VectorXd y(1), mean(m), var(m);
  long before = 0;
  for (int t = 0; t <= 100; ++t) {
    if (t == 1) before = testing::MallocCount();
    y(0) = 5.0 + 0.1 * (t % 7);
    (*cf)->Update(y);
    (*cf)->MeanAndVariance(mean, var);
    (*cf)->PredictBroadcast(f.broadcast, 0.003 * t, 0.009 * t);
  }
  return testing::MallocCount() - before;
}

TEST(EstimationKalmanNoAllocation, DynamicSizeAndCountFilterSteps) {
#ifndef RECRUIT_COUNTS_MALLOC
  GTEST_SKIP() << "malloc is not replaceable here (sanitizer or not glibc)";
#else
  // The counter works: an Eigen heap matrix goes through malloc.
  const long before = testing::MallocCount();
  Eigen::MatrixXd heap = Eigen::MatrixXd::Ones(30, 30);
  EXPECT_GT(testing::MallocCount(), before);
  EXPECT_EQ(heap.sum(), 900.0);
  EXPECT_EQ(MallocsPerDynamicSteps(20, estimation::CovarianceMode::kExtended), 0);
  EXPECT_EQ(MallocsPerDynamicSteps(50, estimation::CovarianceMode::kExtended), 0);
  EXPECT_EQ(MallocsPerDynamicSteps(20, estimation::CovarianceMode::kConservative), 0);
  EXPECT_EQ(MallocsPerCountFilterSteps(20), 0);
  EXPECT_EQ(MallocsPerCountFilterSteps(50), 0);
#endif
}

TEST(EstimationKalmanNoAllocation, FixedSizePredictAndUpdate) {
  EXPECT_EQ(AllocationsPerSteps<2>(estimation::CovarianceMode::kExtended), 0);
  EXPECT_EQ(AllocationsPerSteps<3>(estimation::CovarianceMode::kConservative), 0);
  EXPECT_EQ(AllocationsPerSteps<20>(estimation::CovarianceMode::kExtended), 0);
  EXPECT_EQ(AllocationsPerSteps<20>(estimation::CovarianceMode::kPlain), 0);
  EXPECT_EQ(AllocationsPerSparseSteps(), 0);
  EXPECT_EQ(AllocationsPerBroadcastSteps(), 0);
  // The counter works (a std::vector allocates through operator new). Eigen's own heap
  // matrices go through malloc directly; the fixed-size filter has none (its members are
  // fixed-size Eigen types, checked by the static assertion below).
  const long before = g_allocations.load();
  std::vector<double> heap(100, 1.0);
  EXPECT_GT(g_allocations.load(), before);
  EXPECT_EQ(heap.size(), 100u);
}

}  // namespace
}  // namespace recruit
