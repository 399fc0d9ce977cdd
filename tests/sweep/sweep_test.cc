// The sweep engine with a stand-in run (fast, deterministic per seed): grid expansion, identical
// reports for 1 and 2 threads, resume after an interruption, and the shortest-dT report; sweep
// files (plant axes, samples), shards, and the sensitivities of a synthetic plant whose critical
// dT is known in closed form.
// closed_loop_test.cc repeats the thread-count check with real closed-loop runs.
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
#include "plot/plot_run.h"
#include "plot/render.h"
#include "sim/task.h"
#include "sweep/grid.h"
#include "sweep/latency.h"
#include "sweep/recommend.h"
#include "sweep/sampling.h"
#include "sweep/sweep_file.h"
#include "sweep/sweep_report.h"
#include "sweep/table.h"

namespace recruit::sweep {
namespace file_sweep_test {

namespace fs = std::filesystem;
using namespace ::recruit::sim;  // NOLINT: tasks and runs the sweeps are made of

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
  EXPECT_TRUE(WriteTables(Aggregate(out->runs, crit), crit, dir.string(), "fake").ok());
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
  ASSERT_TRUE(WriteTables(Aggregate(second->runs, crit), crit, dir.string(), "x").ok());
  ASSERT_TRUE(WriteTables(Aggregate(full->runs, crit), crit, clean.string(), "x").ok());
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
  ASSERT_TRUE(WriteTables(cells, crit, dir.string(), "fake").ok());
  const std::string md = *ReadFile((dir / "table.md").string());
  EXPECT_NE(md.find("| output | 0.1 | 2 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| kalman-augmented | 0.1 | 0.25 |"), std::string::npos) << md;
  fs::remove_all(dir);
}

// A cell whose runs track well but heat a wire past its datasheet limit does not meet: the
// recommendation is the shortest dT whose runs stay within the limits, and the report says why.
TEST(Sweep, ADesignPastItsDatasheetLimitsIsNeverRecommended) {
  std::vector<sim::RunSummary> runs;
  for (double dT : {0.5, 1.0, 2.0}) {
    for (int seed = 0; seed < 2; ++seed) {
      sim::RunSummary r;
      r.estimator = "output";
      r.dT = dT;
      r.lambda = 0.2;
      r.seed = seed;
      r.metrics.overshoot = 0.01;  // every cell tracks within the criterion
      r.metrics.settled_fraction = 1;
      sim::BundleSummary b;
      b.max_temperature = 120;
      b.max_wire_stress = 172e6;
      b.peak_temperature = dT < 1 && seed == 1 ? 121 : 110;  // one run of dT 0.5 too hot
      b.peak_wire_stress = 100e6;
      r.bundles = {b};
      runs.push_back(r);
    }
  }
  const TrackingCriterion crit;
  const auto cells = Aggregate(runs, crit);
  ASSERT_EQ(cells.size(), 3u);
  EXPECT_FALSE(cells[0].meets);
  EXPECT_EQ(cells[0].runs_past_limits, 1);
  EXPECT_EQ(cells[0].seeds_meeting, 1);
  EXPECT_GE(cells[0].margin, 0);
  EXPECT_TRUE(cells[1].meets);
  const auto recs = sweep::Recommend(cells);
  ASSERT_EQ(recs.size(), 1u);
  ASSERT_TRUE(recs[0].found);
  EXPECT_EQ(recs[0].dT, 1.0);
  EXPECT_FALSE(recs[0].censored);
  EXPECT_EQ(recs[0].critical_dT, 1.0);
  const auto dir = TempDir("limits");
  fs::create_directories(dir);
  sweep::ReportInput in{"limits", "a test", crit, cells, {}, {}, {}};
  ASSERT_TRUE(sweep::WriteReport(in, dir.string(), plot::RenderFigure).ok());
  const std::string md = *ReadFile((dir / "report.md").string());
  EXPECT_NE(md.find("1 cell had runs past a datasheet limit"), std::string::npos) << md;
  EXPECT_NE(md.find("dT 0.5 (1/2 runs)"), std::string::npos) << md;
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
  // RLIMIT_FSIZE makes writes past a size fail, as a full disk does: the stability map that
  // `recruit sweep` draws with the plot module (sweep::StabilityMapOptions) must return an error
  // and leave no image or temporary file (in a child, so the limit does not leak into the test).
  const auto dir = TempDir("full");
  auto grid = ExpandGrid(Spec());
  auto out = RunSweep(*grid, dir.string(), FakeRun, 2);
  ASSERT_TRUE(out.ok());
  const TrackingCriterion crit;
  const auto cells = Aggregate(out->runs, crit);
  const plot::PlotOptions map = sweep::StabilityMapOptions(dir.string(), "full", 2);
  // First with room, to size the files: the limit lets every text file through and stops the
  // image, so this checks the image's failed write is seen (not only the tables').
  ASSERT_TRUE(WriteTables(cells, crit, dir.string(), "full").ok());
  ASSERT_TRUE(plot::RunPlot(map).ok());
  std::uintmax_t text = 0;
  for (const char* f : {"table.csv", "table.md", "stability.dat"}) {
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
    const bool ok = WriteTables(cells, crit, dir.string(), "full").ok() && plot::RunPlot(map).ok();
    ::_exit(ok ? 1 : 0);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "the report on a full disk claimed success";
  EXPECT_FALSE(fs::exists(dir / "stability.png"));
  for (auto& e : fs::directory_iterator(dir)) {
    EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos) << e.path();
  }
  fs::remove_all(dir);
}

TEST(Sweep, TheStabilityMapIsDrawnWithoutGnuplot) {
  // The map is drawn by the program (plot/stability_map.h), the same PNG whether or not gnuplot
  // is installed: one panel per estimator, 460 px wide each.
  const auto dir = TempDir("png");
  auto grid = ExpandGrid(Spec());
  auto out = RunSweep(*grid, dir.string(), FakeRun, 2);
  ASSERT_TRUE(out.ok());
  const TrackingCriterion crit;
  const std::string title = "it's'; system('x";
  ASSERT_TRUE(WriteTables(Aggregate(out->runs, crit), crit, dir.string(), title).ok());
  EXPECT_FALSE(fs::exists(dir / "stability.gp"));
  auto written = plot::RunPlot(sweep::StabilityMapOptions(dir.string(), title, 2));
  ASSERT_TRUE(written.ok()) << written.error();
  ASSERT_EQ(written->size(), 1u);
  EXPECT_EQ((*written)[0], (dir / "stability.png").string());
  const std::string png = *ReadFile((dir / "stability.png").string());
  ASSERT_GT(png.size(), 1000u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
  // Width and height from the PNG header (big-endian at bytes 16 and 20).
  auto be32 = [&png](size_t at) {
    unsigned v = 0;
    for (size_t i = 0; i < 4; ++i) v = (v << 8) | static_cast<unsigned char>(png[at + i]);
    return v;
  };
  EXPECT_EQ(be32(16), 920u);
  EXPECT_EQ(be32(20), 420u);
  for (auto& e : fs::directory_iterator(dir)) {
    EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos) << e.path();
  }
  fs::remove_all(dir);
}

TEST(Sweep, EveryRunMadeAppendsOneLineToTheProgressLog) {
  const auto dir = TempDir("log");
  auto grid = ExpandGrid(Spec());
  ASSERT_TRUE(ShardOf(*grid, 1, 2).size() > 0);
  ASSERT_TRUE(RunSweep(ShardOf(*grid, 1, 2), dir.string(), FakeRun, 2).ok());
  ASSERT_TRUE(RunSweep(*grid, dir.string(), FakeRun, 2).ok());  // resumes: the other half only
  const std::string log = *ReadFile((dir / "progress.log").string());
  size_t pos = 0, lines = 0;
  while ((pos = log.find('\n', pos)) != std::string::npos) ++pos, ++lines;
  for (const auto& g : *grid) {
    const size_t at = log.find(" " + g.Key() + " ");
    EXPECT_NE(at, std::string::npos) << g.Key();
    EXPECT_EQ(log.find(" " + g.Key() + " ", at + 1), std::string::npos) << "twice: " << g.Key();
  }
  EXPECT_EQ(lines, grid->size());
  EXPECT_NE(log.find(" eta="), std::string::npos);
  fs::remove_all(dir);
}

// --- The latency bound.

TEST(SweepLatency, DelayLoopMatchesItsClosedFormThreshold) {
  // y' = a (1 - y(t - 1)) has a non-oscillating (overshoot-free) step response iff a <= 1/e.
  EXPECT_NEAR(sweep::DelayLoopGainForOvershoot(0.0), 1 / M_E, 3e-3);
  EXPECT_LT(sweep::DelayLoopOvershoot(0.9 / M_E), 1e-9);
  EXPECT_GT(sweep::DelayLoopOvershoot(1.1 / M_E), 1e-4);
  // A larger allowed overshoot allows a larger loop gain, below the stability limit pi/2.
  const double c10 = sweep::DelayLoopGainForOvershoot(0.10);
  EXPECT_NEAR(sweep::DelayLoopOvershoot(c10), 0.10, 1e-6);
  EXPECT_GT(c10, 1 / M_E);
  EXPECT_LT(c10, sweep::DelayLoopGainForOvershoot(0.20));
  EXPECT_LT(sweep::DelayLoopGainForOvershoot(0.20), M_PI / 2);
}

TEST(SweepLatency, BenchForceLatencyEqualsTheOfficialBindingsMeasurement) {
  // Reference: MuJoCo's Python bindings with the plugin library, models/isometric_bench.xml at
  // timestep 0.002, ctrl = 1 held from rest: the tension first reaches half its 8 s value
  // (26.66 N, the same at 30 s) at t = 1.742 s.
  auto task =
      Task::FromFile(std::string(RECRUIT_SOURCE_DIR) + "/models/tasks/isometric_steps.json");
  ASSERT_TRUE(task.ok()) << task.error();
  auto tau = sweep::ForceLatency(*task);
  ASSERT_TRUE(tau.ok()) << tau.error();
  EXPECT_NEAR(*tau, 1.742, 0.0041);
}

// --- Samples: the defining properties, not stored numbers.

TEST(SweepSampling, LatinHypercubePutsOnePointInEveryStratumOfEveryAxis) {
  const int n = 37, d = 4;
  const auto pts = sweep::LatinHypercube(n, d, 5);
  ASSERT_EQ(pts.size(), static_cast<size_t>(n));
  for (int k = 0; k < d; ++k) {
    std::set<int> strata;
    for (const auto& p : pts) {
      ASSERT_GE(p[k], 0.0);
      ASSERT_LT(p[k], 1.0);
      strata.insert(static_cast<int>(p[k] * n));
    }
    EXPECT_EQ(strata.size(), static_cast<size_t>(n)) << "axis " << k;
  }
  EXPECT_EQ(sweep::LatinHypercube(n, d, 5), pts);  // seeded: the same again
  EXPECT_NE(sweep::LatinHypercube(n, d, 6), pts);
}

TEST(SweepSampling, SobolFirstTwoDimensionsFormAZeroMTwoNet) {
  // Every 2^m-point prefix of a Sobol sequence stratifies each axis into 2^m equal intervals, and
  // its first two dimensions are a (0, m, 2)-net: each elementary box of area 2^-m (2^a x 2^(m-a)
  // boxes) holds exactly one point. A digital shift (seed != 0) keeps both properties.
  for (std::uint64_t seed : {0ull, 3ull}) {
    const int m = 6, n = 1 << m;
    auto pts = sweep::Sobol(n, sweep::MaxSobolDims(), seed);
    ASSERT_TRUE(pts.ok()) << pts.error();
    for (int k = 0; k < sweep::MaxSobolDims(); ++k) {
      std::set<int> strata;
      for (const auto& p : *pts) strata.insert(static_cast<int>(p[k] * n));
      EXPECT_EQ(strata.size(), static_cast<size_t>(n)) << "axis " << k << " seed " << seed;
    }
    for (int a = 0; a <= m; ++a) {
      std::set<std::pair<int, int>> boxes;
      for (const auto& p : *pts) {
        boxes.insert({static_cast<int>(p[0] * (1 << a)), static_cast<int>(p[1] * (1 << (m - a)))});
      }
      EXPECT_EQ(boxes.size(), static_cast<size_t>(n)) << "2^" << a << " x 2^" << m - a;
    }
  }
  EXPECT_FALSE(sweep::Sobol(4, sweep::MaxSobolDims() + 1, 1).ok());
}

TEST(SweepSampling, SobolWithoutShiftEqualsSciPysJoeKuoSequence) {
  // Reference: scipy 1.17 `qmc.Sobol(d=12, scramble=False).random(64)` (Joe-Kuo 6.21201 direction
  // numbers, Gray-code order), rows 5, 38 and 63. The whole 64 x 12 block was compared once too.
  const std::vector<std::pair<int, std::vector<double>>> ref = {
      {5, {0.875, 0.875, 0.125, 0.375, 0.875, 0.625, 0.875, 0.375, 0.375, 0.125, 0.375, 0.875}},
      {38,
       {0.671875, 0.390625, 0.328125, 0.171875, 0.515625, 0.046875, 0.921875, 0.546875, 0.859375,
        0.421875, 0.265625, 0.328125}},
      {63,
       {0.015625, 0.796875, 0.359375, 0.453125, 0.859375, 0.140625, 0.578125, 0.140625, 0.828125,
        0.578125, 0.421875, 0.671875}}};
  auto pts = sweep::Sobol(64, 12, 0);
  ASSERT_TRUE(pts.ok());
  for (const auto& [row, values] : ref) EXPECT_EQ((*pts)[row], values) << "row " << row;
}

// --- Sweep files and plant points.

const char* kTaskText = R"({"name": "t", "model": "m.xml", "tracked": "force", "agonist": "b",
  "duration": 10, "reference": {"type": "steps", "times": [1], "values": [5]},
  "sensor": {"noise_std": 0.05, "resolution": 0.0125},
  "payloads": [{"body": "p", "mass": 0.1}]})";
const char* kModelText = R"(<mujoco><extension><plugin plugin="recruit.sma">
  <instance name="units_a"><config key="units" value="60"/></instance>
  <instance name="units_b"/></plugin></extension></mujoco>)";

Result<sweep::SweepFile> Parse(const std::string& text) {
  return sweep::SweepFile::FromJsonText(text, "s.json");
}

TEST(SweepFile, GridOfPlantAxesIsTheCartesianProductFirstAxisOutermost) {
  auto f = Parse(R"({"controller": {"dT": {"range": [0.25, 2], "steps": 4, "scale": "log"}},
    "plant": {"axes": [
      {"name": "N", "path": "model:units_a/units", "values": [30, 60], "integer": true},
      {"name": "noise", "path": "/sensor/noise_std", "range": [0.1, 0.3], "steps": 3}]}})");
  ASSERT_TRUE(f.ok()) << f.error();
  ASSERT_EQ(f->dTs.size(), 4u);
  EXPECT_NEAR(f->dTs[1], 0.5, 1e-12);
  EXPECT_NEAR(f->dTs[3], 2.0, 1e-12);
  auto pts = sweep::PlantPoints(*f);
  ASSERT_TRUE(pts.ok());
  ASSERT_EQ(pts->size(), 6u);
  EXPECT_EQ((*pts)[0].values[0].second, 30);
  EXPECT_NEAR((*pts)[1].values[1].second, 0.2, 1e-12);
  EXPECT_EQ((*pts)[3].values[0].second, 60);
  auto in = sweep::ApplyPlantPoint(kTaskText, kModelText, f->axes, (*pts)[4], "s.json");
  ASSERT_TRUE(in.ok()) << in.error();
  EXPECT_TRUE(in->model_edited);
  EXPECT_NE(in->model_text.find(R"(<config key="units" value="60"/>)"), std::string::npos);
  EXPECT_NEAR(nlohmann::json::parse(in->task_text)["sensor"]["noise_std"].get<double>(), 0.2,
              1e-12);
}

TEST(SweepFile, PluginConfigIsReplacedOrAddedInTheNamedInstanceOnly) {
  auto a = sweep::SetPluginConfig(kModelText, "units_a", "units", "90");
  ASSERT_TRUE(a.ok());
  EXPECT_NE(a->find(R"(<instance name="units_a"><config key="units" value="90"/>)"),
            std::string::npos);
  auto b = sweep::SetPluginConfig(kModelText, "units_a", "current", "0.2");
  ASSERT_TRUE(b.ok());
  EXPECT_NE(b->find(R"(<config key="current" value="0.2"/>)"), std::string::npos);
  EXPECT_NE(b->find(R"(<config key="units" value="60"/>)"), std::string::npos);
  auto c = sweep::SetPluginConfig(kModelText, "units_b", "units", "10");
  ASSERT_TRUE(c.ok());
  EXPECT_NE(c->find(R"(<instance name="units_b"><config key="units" value="10"/></instance>)"),
            std::string::npos);
  auto d = sweep::SetPluginConfig(kModelText, "nope", "units", "10");
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.error().find("units_a, units_b"), std::string::npos) << d.error();
}

TEST(SweepFile, BadPathsAndValuesNameTheFileTheAxisAndTheValue) {
  const std::string axes_head = R"({"plant": {"axes": [{"name": "x", "path": )";
  struct Case {
    std::string path_and_values, expect;
  };
  for (const Case& c : std::vector<Case>{
           {R"("/bundles/0/N", "values": [3]}]}})", "no '/bundles/0'"},
           {R"("/reference/times/4", "values": [3]}]}})", "index 4 is past the end"},
           {R"("/reference/type", "values": [3]}]}})", "not a number"},
           {R"("/payloads/0/mass", "values": [3]}]}})", ""},
           {R"("model:units_c/units", "values": [3]}]}})", "no plugin instance 'units_c'"}}) {
    auto f = Parse(axes_head + c.path_and_values);
    ASSERT_TRUE(f.ok()) << f.error();
    auto pts = sweep::PlantPoints(*f);
    auto in = sweep::ApplyPlantPoint(kTaskText, kModelText, f->axes, pts->at(0), "s.json");
    if (c.expect.empty()) {
      EXPECT_TRUE(in.ok()) << in.error();
      continue;
    }
    ASSERT_FALSE(in.ok()) << c.path_and_values;
    EXPECT_NE(in.error().find("s.json"), std::string::npos) << in.error();
    EXPECT_NE(in.error().find("axis 'x'"), std::string::npos) << in.error();
    EXPECT_NE(in.error().find("value 3"), std::string::npos) << in.error();
    EXPECT_NE(in.error().find(c.expect), std::string::npos) << in.error();
  }
  for (const Case& c : std::vector<Case>{
           {R"({"plant": {"axes": [{"path": "sensor/x", "values": [1]}]}})", "neither a JSON"},
           {R"({"plant": {"axes": [{"path": "/a", "range": [1, 2]}]}})", "needs \"steps\""},
           {R"({"plant": {"axes": [{"path": "/a", "values": ["big"]}]}})", "\"big\""},
           {R"({"plant": {"axes": [{"path": "/controller/dT", "values": [1]}]}})", "controller"},
           {R"({"plant": {"sampling": "lhs", "axes": []}})", "samples"},
           {R"({"controller": {"lambda": [0.2, 1.5]}})", "lambda: value 1.5"},
           {R"({"controller": {"estimator": ["kalman"]}})", "\"kalman\""},
           {R"({"plant": {"axes": [], "colour": 1}})", "unknown field 'colour'"}}) {
    auto f = Parse(c.path_and_values);
    ASSERT_FALSE(f.ok()) << c.path_and_values;
    EXPECT_NE(f.error().find("s.json"), std::string::npos) << f.error();
    EXPECT_NE(f.error().find(c.expect), std::string::npos) << f.error();
  }
}

TEST(SweepFile, SamplesMapTheUnitCubeOntoTheRangesAndAreSeeded) {
  const std::string text = R"({"plant": {"sampling": "SAMPLING", "samples": 16, "seed": 4,
    "axes": [{"name": "N", "path": "model:units_a/units", "range": [30, 120], "integer": true},
             {"name": "noise", "path": "/sensor/noise_std", "range": [0.01, 1], "scale": "log"}]}})";
  for (const std::string sampling : {"lhs", "sobol"}) {
    std::string t = text;
    t.replace(t.find("SAMPLING"), 8, sampling);
    auto f = Parse(t);
    ASSERT_TRUE(f.ok()) << f.error();
    auto pts = sweep::PlantPoints(*f);
    ASSERT_TRUE(pts.ok());
    ASSERT_EQ(pts->size(), 16u);
    int low_decade = 0;
    for (const auto& p : *pts) {
      EXPECT_GE(p.values[0].second, 30);
      EXPECT_LE(p.values[0].second, 120);
      EXPECT_EQ(p.values[0].second, std::round(p.values[0].second));
      EXPECT_GE(p.values[1].second, 0.01);
      EXPECT_LT(p.values[1].second, 1);
      low_decade += p.values[1].second < 0.1;
    }
    EXPECT_EQ(low_decade, 8) << sampling;  // log scale: half the strata lie below 0.1
    auto again = sweep::PlantPoints(*f);
    for (size_t i = 0; i < pts->size(); ++i) EXPECT_EQ((*again)[i].values, (*pts)[i].values);
  }
}

// --- Shards.

TEST(SweepShard, ShardsPartitionTheGridAndMergeToTheUnshardedTable) {
  SweepSpec spec = Spec();
  spec.plant = {PlantPoint{{{"N", 30}}}, PlantPoint{{{"N", 60}}}, PlantPoint{{{"N", 90}}}};
  auto grid = ExpandGrid(spec);
  ASSERT_TRUE(grid.ok());
  EXPECT_EQ(grid->size(), 3 * Spec().dTs.size() * 2 * 2 * 3);
  EXPECT_EQ((*grid)[0].Key(), "p0000_dT0.25_l0.1_output_s0");
  const int n = 5;
  std::vector<RunSummary> merged(grid->size());
  std::set<int> seen;
  for (int k = 1; k <= n; ++k) {
    const auto dir = TempDir("shard" + std::to_string(k));
    const auto shard = ShardOf(*grid, k, n);
    auto out = RunSweep(shard, dir.string(), FakeRun, 2);
    ASSERT_TRUE(out.ok()) << out.error();
    for (size_t i = 0; i < shard.size(); ++i) {
      EXPECT_TRUE(seen.insert(shard[i].index).second) << "run in two shards";
      merged[shard[i].index] = out->runs[i];
    }
    fs::remove_all(dir);
  }
  EXPECT_EQ(seen.size(), grid->size());
  const auto whole = TempDir("unsharded");
  auto all = RunSweep(*grid, whole.string(), FakeRun, 2);
  ASSERT_TRUE(all.ok());
  const TrackingCriterion crit;
  const auto merged_dir = TempDir("merged");
  fs::create_directories(merged_dir);
  ASSERT_TRUE(WriteTables(Aggregate(*grid, merged, crit), crit, merged_dir.string(), "x").ok());
  ASSERT_TRUE(WriteTables(Aggregate(*grid, all->runs, crit), crit, whole.string(), "x").ok());
  EXPECT_EQ(*ReadFile((merged_dir / "table.csv").string()),
            *ReadFile((whole / "table.csv").string()));
  EXPECT_NE(ReadFile((whole / "table.csv").string())->find("plant,N,dT"), std::string::npos);
  EXPECT_FALSE(fs::exists(whole / "stability.gp"));  // plant axes: the report's figures instead
  EXPECT_FALSE(ParseShard("0/4").ok());
  EXPECT_FALSE(ParseShard("5/4").ok());
  EXPECT_FALSE(ParseShard("2/4x").ok());
  EXPECT_EQ(ParseShard("2/4")->first, 2);
  fs::remove_all(whole);
  fs::remove_all(merged_dir);
}

// --- Sensitivities of a synthetic plant with a known answer.
//
// The plant's critical dT is dT* = c * a^alpha * b^beta and a run's overshoot is
// 0.1 - k * ln(dT / dT*) (settled always): the margin is k * ln(dT / dT*), linear in ln dT, so
// the log-dT interpolation of its zero crossing is exact, the recommended dT is the shortest grid
// dT >= dT*, and the elasticities of dT* to a and b are exactly alpha and beta (b's range is
// negative, so it is fitted on b itself: d ln dT* / db = beta).
constexpr double kC = 0.4, kAlpha = 0.5, kBeta = -0.3, kK = 0.05;
double SyntheticCritical(double a, double b) {
  return kC * std::pow(a, kAlpha) * std::exp(kBeta * b);
}

Result<RunSummary> SyntheticRun(const SweepRun& g) {
  RunSummary s;
  s.task = "synthetic";
  s.estimator = g.estimator;
  s.dT = g.dT;
  s.lambda = g.lambda;
  s.seed = g.seed;
  s.duration = 1;
  const double crit = SyntheticCritical(g.plant_values.at(0).second, g.plant_values.at(1).second);
  s.metrics.overshoot = 0.1 - kK * std::log(g.dT / crit);
  s.metrics.settled_fraction = 1;
  return s;
}

TEST(SweepSensitivity, SyntheticPlantGivesItsClosedFormElasticities) {
  SweepSpec spec;
  for (int i = -4; i <= 4; ++i) spec.dTs.push_back(std::pow(2.0, i * 0.5));
  spec.lambdas = {0.2};
  spec.estimators = {"output"};
  spec.seeds = 2;
  for (double a : {1.0, 2.0, 4.0, 8.0}) {
    for (double b : {-1.0, 0.0, 1.5}) spec.plant.push_back(PlantPoint{{{"a", a}, {"b", b}}});
  }
  auto grid = ExpandGrid(spec);
  ASSERT_TRUE(grid.ok());
  const auto dir = TempDir("synthetic");
  auto out = RunSweep(*grid, dir.string(), SyntheticRun, 2);
  ASSERT_TRUE(out.ok()) << out.error();
  const TrackingCriterion crit;  // overshoot <= 0.1: margin = k ln(dT / dT*)
  const auto cells = Aggregate(*grid, out->runs, crit);
  const auto recs = sweep::Recommend(cells);
  ASSERT_EQ(recs.size(), spec.plant.size());
  for (const auto& r : recs) {
    const double expected = SyntheticCritical(r.plant_values[0].second, r.plant_values[1].second);
    ASSERT_TRUE(r.found);
    if (r.censored) {
      EXPECT_LE(expected, spec.dTs.front() * (1 + 1e-12));
      continue;
    }
    EXPECT_NEAR(r.critical_dT, expected, 1e-9 * expected);
    // The shortest grid dT at or above dT*, with margin k ln(dT / dT*) and both seeds meeting.
    double shortest = 1e9;
    for (double dT : spec.dTs) {
      if (dT >= expected) shortest = std::min(shortest, dT);
    }
    EXPECT_DOUBLE_EQ(r.dT, shortest);
    EXPECT_NEAR(r.margin, kK * std::log(shortest / expected), 1e-12);
    EXPECT_EQ(r.seeds_meeting, 2);
    EXPECT_DOUBLE_EQ(r.confidence, 1.0);  // no spread over seeds
  }
  const auto sens = sweep::Sensitivities(recs);
  ASSERT_EQ(sens.size(), 2u);
  // Sorted by effect over the swept range: a spans ln 8 -> |0.5| ln 8 = 1.04; b spans 2.5 ->
  // |-0.3| * 2.5 = 0.75.
  EXPECT_EQ(sens[0].axis, "a");
  EXPECT_TRUE(sens[0].log_axis);
  EXPECT_NEAR(sens[0].slope, kAlpha, 1e-9);
  EXPECT_NEAR(sens[0].effect, std::pow(8.0, kAlpha), 1e-9);
  EXPECT_EQ(sens[1].axis, "b");
  EXPECT_FALSE(sens[1].log_axis);
  EXPECT_NEAR(sens[1].slope, kBeta, 1e-9);

  // The report: the table names every plant point, the HTML embeds its figures.
  sweep::ReportInput in{"synthetic", "a test", crit, cells, {}, {}, {}};
  ASSERT_TRUE(sweep::WriteReport(in, dir.string(), plot::RenderFigure).ok());
  const std::string md = *ReadFile((dir / "report.md").string());
  EXPECT_NE(md.find("| output | 0.2 | a | +0.500 (d ln dT*/d ln x)"), std::string::npos) << md;
  EXPECT_NE(ReadFile((dir / "report.html").string())->find("data:image/png;base64,iVBORw0KGgo"),
            std::string::npos);
  for (const char* f : {"margin.png", "margin.svg", "critical_dt.png", "critical_dt.svg"}) {
    EXPECT_GT(fs::file_size(dir / f), 1000u) << f;
  }
  fs::remove_all(dir);
}

}  // namespace file_sweep_test
}  // namespace recruit::sweep
