// The sweep engine with a stand-in run (fast, deterministic per seed): grid expansion, identical
// reports for 1 and 2 threads, resume after an interruption, and the shortest-dT report.
// closed_loop_test.cc repeats the thread-count check with real closed-loop runs.
#include "sim/sweep.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <set>
#include <thread>

#include "common/atomic_file.h"
#include "common/rng.h"

namespace recruit::sim {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("recruit_sweep_test_" + name);
  fs::remove_all(p);
  return p;
}

// Metrics drawn from the run's own seed, overshoot growing as dT shrinks; a sleep that depends
// on the index scrambles the order in which runs finish.
Result<RunSummary> FakeRun(const SweepRun& g) {
  std::this_thread::sleep_for(std::chrono::microseconds(200 * ((g.index * 7919) % 5)));
  Rng rng(g.seed);
  RunSummary s;
  s.task = "fake";
  s.estimator = g.estimator;
  s.dT = g.dT;
  s.lambda = g.lambda;
  s.seed = g.seed;
  s.duration = 10;
  s.unit = "N";
  const double base = g.estimator == "kalman-augmented" ? 0.02 : 0.3 / g.dT;
  s.metrics.overshoot = base * g.lambda / 0.2 + 0.01 * rng.Uniform();
  s.metrics.settled_fraction = 1.0;
  s.metrics.settling_time = 3 * rng.Uniform();
  s.metrics.tracking_rmse = rng.Uniform();
  s.wall_seconds = rng.Uniform();  // differs between runs, must not reach the report
  return s;
}

SweepSpec Spec() {
  SweepSpec spec;
  spec.dTs = {0.25, 0.5, 1.0, 2.0};
  spec.lambdas = {0.1, 0.2};
  spec.estimators = {"output", "kalman-augmented"};
  spec.seeds = 3;
  spec.base_seed = 11;
  return spec;
}

TEST(Sweep, GridOrderAndSeedsAreDerivedPerSeedIndex) {
  auto grid = ExpandGrid(Spec());
  ASSERT_TRUE(grid.ok()) << grid.error();
  ASSERT_EQ(grid->size(), 4u * 2 * 2 * 3);
  EXPECT_DOUBLE_EQ((*grid)[0].dT, 0.25);
  EXPECT_EQ((*grid)[0].estimator, "output");
  EXPECT_EQ((*grid)[1].seed_index, 1);
  EXPECT_EQ((*grid)[1].seed, Rng::DeriveSeed(11, 1));
  // Common random numbers: the same seed index has the same seed in every cell.
  EXPECT_EQ((*grid)[3].seed, (*grid)[0].seed);
  std::set<std::string> keys;
  for (const auto& r : *grid) keys.insert(r.Key());
  EXPECT_EQ(keys.size(), grid->size());
}

TEST(Sweep, BadGridIsRejected) {
  SweepSpec s = Spec();
  s.lambdas = {0.0};
  auto g = ExpandGrid(s);
  ASSERT_FALSE(g.ok());
  EXPECT_NE(g.error().find("lambda"), std::string::npos);
  s = Spec();
  s.dTs = {};
  EXPECT_FALSE(ExpandGrid(s).ok());
}

std::string RunAndReport(const fs::path& dir, int threads) {
  auto grid = ExpandGrid(Spec());
  auto out = RunSweep(*grid, dir.string(), FakeRun, threads);
  EXPECT_TRUE(out.ok()) << out.error();
  const TrackingCriterion crit;
  EXPECT_TRUE(WriteSweepReport(Aggregate(out->runs, crit), crit, dir.string(), "fake").ok());
  return *ReadFile((dir / "table.csv").string()) + *ReadFile((dir / "table.md").string());
}

TEST(Sweep, ReportIsByteIdenticalForOneAndTwoThreads) {
  const auto a = TempDir("t1"), b = TempDir("t2");
  const std::string one = RunAndReport(a, 1);
  const std::string two = RunAndReport(b, 2);
  EXPECT_FALSE(one.empty());
  EXPECT_EQ(one, two);
  fs::remove_all(a);
  fs::remove_all(b);
}

TEST(Sweep, InterruptedSweepResumesWithoutRedoingFinishedRuns) {
  const auto dir = TempDir("resume");
  auto grid = ExpandGrid(Spec());
  ASSERT_TRUE(grid.ok());
  // First attempt: runs fail ("interrupt") after 10 successes.
  std::atomic<int> calls{0};
  auto failing = [&](const SweepRun& g) -> Result<RunSummary> {
    if (calls++ >= 10) return Error{"interrupted"};
    return FakeRun(g);
  };
  auto first = RunSweep(*grid, dir.string(), failing, 1);
  ASSERT_FALSE(first.ok());
  int recorded = 0;
  for (auto& e : fs::directory_iterator(dir / "runs")) recorded += e.path().extension() == ".json";
  EXPECT_EQ(recorded, 10);

  // Second attempt: only the missing runs are made.
  std::atomic<int> second_calls{0};
  std::set<std::string> redone;
  std::mutex mu;
  auto counting = [&](const SweepRun& g) {
    ++second_calls;
    std::lock_guard<std::mutex> l(mu);
    redone.insert(g.Key());
    return FakeRun(g);
  };
  auto second = RunSweep(*grid, dir.string(), counting, 2);
  ASSERT_TRUE(second.ok()) << second.error();
  EXPECT_EQ(second->reused, 10);
  EXPECT_EQ(second->executed, static_cast<int>(grid->size()) - 10);
  EXPECT_EQ(second_calls.load(), static_cast<int>(grid->size()) - 10);
  // No run finished in the first attempt was made again: the first 10 grid points (one thread
  // takes them in order) are not among the redone ones.
  for (int i = 0; i < 10; ++i) EXPECT_EQ(redone.count((*grid)[i].Key()), 0u) << i;
  // The result equals an uninterrupted sweep's.
  const TrackingCriterion crit;
  const auto clean = TempDir("resume_clean");
  auto full = RunSweep(*grid, clean.string(), FakeRun, 2);
  ASSERT_TRUE(full.ok());
  ASSERT_TRUE(WriteSweepReport(Aggregate(second->runs, crit), crit, dir.string(), "x").ok());
  ASSERT_TRUE(WriteSweepReport(Aggregate(full->runs, crit), crit, clean.string(), "x").ok());
  EXPECT_EQ(*ReadFile((dir / "table.csv").string()), *ReadFile((clean / "table.csv").string()));

  // A third attempt makes nothing.
  std::atomic<int> third_calls{0};
  auto third = RunSweep(
      *grid, dir.string(),
      [&](const SweepRun& g) {
        ++third_calls;
        return FakeRun(g);
      },
      2);
  ASSERT_TRUE(third.ok());
  EXPECT_EQ(third_calls.load(), 0);
  EXPECT_EQ(third->reused, static_cast<int>(grid->size()));
  fs::remove_all(dir);
  fs::remove_all(clean);
}

TEST(Sweep, ARecordOfAnotherSeedIsNotReused) {
  const auto dir = TempDir("stale");
  auto grid = ExpandGrid(Spec());
  ASSERT_TRUE(RunSweep(*grid, dir.string(), FakeRun, 2).ok());
  SweepSpec other = Spec();
  other.base_seed = 12;  // same keys, different seeds
  auto grid2 = ExpandGrid(other);
  auto out = RunSweep(*grid2, dir.string(), FakeRun, 2);
  ASSERT_TRUE(out.ok());
  EXPECT_EQ(out->reused, 0);
  fs::remove_all(dir);
}

TEST(Sweep, ShortestDtIsTheShortestThatMeetsTheCriterion) {
  // Fake overshoot = 0.3 / dT * lambda / 0.2 + U(0, 0.01) for output: at lambda 0.1,
  // 0.15 / dT <= 0.10 needs dT >= 1.5 -> 2.0 meets, 1.0 does not (0.15).
  auto grid = ExpandGrid(Spec());
  const auto dir = TempDir("shortest");
  auto out = RunSweep(*grid, dir.string(), FakeRun, 2);
  ASSERT_TRUE(out.ok());
  const TrackingCriterion crit;
  const auto cells = Aggregate(out->runs, crit);
  ASSERT_EQ(cells.size(), 16u);
  for (const auto& c : cells) {
    EXPECT_EQ(c.seeds, 3);
    if (c.estimator == "output" && c.lambda == 0.1) {
      EXPECT_EQ(c.meets, c.dT >= 2.0) << c.dT;
    }
    if (c.estimator == "kalman-augmented") {
      EXPECT_TRUE(c.meets);
    }
  }
  ASSERT_TRUE(WriteSweepReport(cells, crit, dir.string(), "fake").ok());
  const std::string md = *ReadFile((dir / "table.md").string());
  EXPECT_NE(md.find("| output | 0.1 | 2 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| kalman-augmented | 0.1 | 0.25 |"), std::string::npos) << md;
  fs::remove_all(dir);
}

TEST(Sweep, ARecordMadeFromOtherInputsIsNotReused) {
  // Same grid points and seeds, but the inputs changed (an edited task file): the input hash
  // differs, so every run is made again; unchanged inputs reuse every run.
  const auto dir = TempDir("edited");
  auto grid = ExpandGrid(Spec());
  for (auto& g : *grid) g.input_hash = "hash-of-task-v1";
  ASSERT_TRUE(RunSweep(*grid, dir.string(), FakeRun, 2).ok());
  auto same = RunSweep(*grid, dir.string(), FakeRun, 2);
  ASSERT_TRUE(same.ok());
  EXPECT_EQ(same->reused, static_cast<int>(grid->size()));
  for (auto& g : *grid) g.input_hash = "hash-of-task-v2";
  auto edited = RunSweep(*grid, dir.string(), FakeRun, 2);
  ASSERT_TRUE(edited.ok());
  EXPECT_EQ(edited->reused, 0);
  EXPECT_EQ(edited->executed, static_cast<int>(grid->size()));
  fs::remove_all(dir);
}

TEST(Sweep, AReportOnAFullDiskFails) {
  // RLIMIT_FSIZE (inherited by gnuplot) makes writes past a size fail, as a full disk does: the
  // report must return an error (in a child, so the limit does not leak into the test).
  const auto dir = TempDir("full");
  auto grid = ExpandGrid(Spec());
  auto out = RunSweep(*grid, dir.string(), FakeRun, 2);
  ASSERT_TRUE(out.ok());
  const TrackingCriterion crit;
  const auto cells = Aggregate(out->runs, crit);
  // First with room, to size the files: the limit lets every text file through and stops the
  // image, so this checks gnuplot's failure is seen (not only our own writes').
  ASSERT_TRUE(WriteSweepReport(cells, crit, dir.string(), "full").ok());
  if (!fs::exists(dir / "stability.png")) GTEST_SKIP() << "gnuplot missing";
  std::uintmax_t text = 0;
  for (const char* f : {"table.csv", "table.md", "stability.dat", "stability.gp"}) {
    text = std::max(text, fs::file_size(dir / f));
  }
  const std::uintmax_t png = fs::file_size(dir / "stability.png");
  ASSERT_GT(png, text + 200);
  fs::remove(dir / "stability.png");
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::signal(SIGXFSZ, SIG_IGN);
    rlimit lim{text + 100, text + 100};
    ::setrlimit(RLIMIT_FSIZE, &lim);
    ::_exit(WriteSweepReport(cells, crit, dir.string(), "full").ok() ? 1 : 0);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "the report on a full disk claimed success";
  EXPECT_FALSE(fs::exists(dir / "stability.png"));
  for (auto& e : fs::directory_iterator(dir)) {
    EXPECT_EQ(e.path().string().find(".tmp."), std::string::npos) << e.path();
  }
  fs::remove_all(dir);
}

TEST(Sweep, TheStabilityMapIsMadeOrItsFailureReported) {
  // With room on disk the map is a non-empty PNG (gnuplot installed) or the report says why.
  const auto dir = TempDir("png");
  auto grid = ExpandGrid(Spec());
  auto out = RunSweep(*grid, dir.string(), FakeRun, 2);
  ASSERT_TRUE(out.ok());
  const TrackingCriterion crit;
  // A title with a quote must not break (or inject into) the gnuplot script.
  ASSERT_TRUE(
      WriteSweepReport(Aggregate(out->runs, crit), crit, dir.string(), "it's'; system('x").ok());
  if (::system("command -v gnuplot > /dev/null 2>&1") == 0) {
    ASSERT_TRUE(fs::exists(dir / "stability.png"));
    EXPECT_GT(fs::file_size(dir / "stability.png"), 1000u);
  }
  for (auto& e : fs::directory_iterator(dir)) {
    EXPECT_EQ(e.path().string().find(".tmp."), std::string::npos) << e.path();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace recruit::sim
