// The tune's judgement of runs: each part of the criterion counted on the seeds that break it,
// the overshoot's statistics over every step of every seed (against a direct computation), and
// the datasheet limits (a run past one never meets).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <tuple>

#include "sweep/tune.h"

namespace recruit::sweep {
namespace file_tune_seed_test {

sim::RunSummary FakeRun(std::vector<double> step_overshoots, double settled, double peak_c = 50) {
  sim::RunSummary r;
  double sum = 0;
  for (double x : step_overshoots) {
    sim::StepResponse s;
    s.step = {5, 0, 10, 20};
    s.overshoot = x;
    r.steps.push_back(s);
    sum += x;
  }
  r.metrics.overshoot = sum / step_overshoots.size();
  r.metrics.max_overshoot = *std::max_element(step_overshoots.begin(), step_overshoots.end());
  r.metrics.settled_fraction = settled;
  r.metrics.estimator_rmse = 2;
  r.metrics.mean_nees = std::nan("");
  sim::BundleSummary b;
  b.peak_temperature = peak_c;
  b.max_temperature = 100;
  b.peak_wire_stress = 100e6;
  b.max_wire_stress = 200e6;
  r.bundles.push_back(b);
  return r;
}

TEST(TuneSeed, EachPartOfTheCriterionIsCountedOnItsSeeds) {
  TuneCriterion c;  // 10 % mean overshoot, 90 % settled
  c.max_step_overshoot = 0.2;
  std::vector<sim::RunSummary> runs = {
      FakeRun({0.02, 0.04}, 1.0),        // meets
      FakeRun({0.15, 0.12}, 1.0),        // mean overshoot 13.5 %
      FakeRun({0.01, 0.25}, 1.0),        // mean 13 % and worst step 25 %
      FakeRun({0.0, 0.219}, 1.0),        // mean 10.95 % and worst 21.9 %
      FakeRun({0.0, 0.0}, 0.5),          // settling
      FakeRun({0.01, 0.02}, 1.0, 120)};  // 120 C against a 100 C limit
  runs[4].warnings = {"bundle: its identified model explains R^2 = 0.50 of held-out force",
                      "bundle: peak unit temperature 120.0 C exceeds the limit 100.0 C"};
  runs[5].warnings = runs[4].warnings;
  EXPECT_TRUE(CheckSeed(runs[0], c).meets());
  EXPECT_TRUE(CheckSeed(runs[5], c).limits);
  EXPECT_FALSE(CheckSeed(runs[5], c).meets());
  TuneSettings s;
  const DtRow row = SummarizeDt(0.5, runs, c, s);
  EXPECT_EQ(row.seeds, 6);
  EXPECT_EQ(row.meeting, 1);
  EXPECT_EQ(row.fail_overshoot, 3);
  EXPECT_EQ(row.fail_worst_step, 2);
  EXPECT_EQ(row.fail_settling, 1);
  EXPECT_EQ(row.fail_limits, 1);
  EXPECT_DOUBLE_EQ(row.worst_temperature_ratio, 1.2);
  EXPECT_DOUBLE_EQ(row.worst_stress_ratio, 0.5);
  // 12 steps: mean, worst, and the 95th percentile interpolated between the sorted 11th and 12th
  // (position 0.95 * 11 = 10.45).
  std::vector<double> all = {0.02, 0.04, 0.15, 0.12, 0.01, 0.25, 0.0, 0.219, 0.0, 0.0, 0.01, 0.02};
  double sum = 0;
  for (double x : all) sum += x;
  std::sort(all.begin(), all.end());
  EXPECT_NEAR(row.overshoot_mean, sum / 12, 1e-12);
  EXPECT_DOUBLE_EQ(row.overshoot_worst, 0.25);
  EXPECT_NEAR(row.overshoot_p95, all[10] + 0.45 * (all[11] - all[10]), 1e-12);
  // 1 of 6: the Wilson interval of the report.
  const Interval w = WilsonInterval(1, 6, NormalQuantile(0.95));
  EXPECT_DOUBLE_EQ(row.fraction.lo, w.lo);
  EXPECT_EQ(row.verdict, Verdict::kFails);
  EXPECT_TRUE(std::isnan(row.mean_nees));
  // The model-quality warning counted on its two runs; the limit line is counted as limits.
  ASSERT_EQ(row.warnings.size(), 1u);
  EXPECT_EQ(row.warnings[0].second, 2);
}

TEST(TuneSeed, WithoutAStepLimitTheWorstStepPasses) {
  TuneCriterion c;  // no limit on the worst step: the 21.9 % step in a 9 % mean passes
  EXPECT_TRUE(CheckSeed(FakeRun({0.0, 0.05, 0.219, 0.1}, 1.0), c).meets());
  c.max_step_overshoot = 0.2;
  EXPECT_FALSE(CheckSeed(FakeRun({0.0, 0.05, 0.219, 0.1}, 1.0), c).meets());
}

TEST(TuneSeed, TheSweepReportGivesEachCellsReasons) {
  // Two cells of a sweep grid (dT 0.5 and 1, three seeds each), runs in grid order.
  std::vector<SweepRun> grid;
  std::vector<sim::RunSummary> runs;
  for (double dT : {0.5, 1.0}) {
    for (int seed = 0; seed < 3; ++seed) {
      SweepRun g;
      g.dT = dT;
      g.lambda = 0.2;
      g.estimator = "output";
      g.seed_index = seed;
      grid.push_back(g);
      // At 0.5 s two seeds overshoot; at 1 s one leaves half its steps unsettled.
      runs.push_back(dT < 1 ? FakeRun({seed < 2 ? 0.3 : 0.01, 0.02}, 1.0)
                            : FakeRun({0.01, 0.02}, seed == 0 ? 0.5 : 1.0));
    }
  }
  const std::string md = SeedReasonsMarkdown(grid, runs, TrackingCriterion{});
  // At 0.5 s the steps are 0.3, 0.02, 0.3, 0.02, 0.01, 0.02: mean 0.67 / 6 = 11.2 %, and the 95th
  // percentile at sorted position 0.95 * 5 = 4.75 lies between the two 0.3 steps.
  const double z = NormalQuantile(0.95);
  const Interval a = WilsonInterval(1, 3, z), b = WilsonInterval(2, 3, z);
  EXPECT_NE(
      md.find(fmt::format("| 0.5 | 1/3 ({:.0f}-{:.0f} %) | overshoot 2/3 | 11.2 / 30.0 / 30.0 |",
                          100 * a.lo, 100 * a.hi)),
      std::string::npos)
      << md;
  EXPECT_NE(
      md.find(fmt::format("| 1 | 2/3 ({:.0f}-{:.0f} %) | settling 1/3 |", 100 * b.lo, 100 * b.hi)),
      std::string::npos)
      << md;
}

// A search's column from (lattice index, seeds, seeds meeting, peak temperature, failing seeds'
// step overshoot), its window found as Tune finds it; failing seeds fail on settling (and on
// overshoot when theirs is above 10 %).
TuneColumn Column(const std::vector<std::tuple<int, int, int, double, double>>& cells,
                  const TuneDefinition& d, const DtLattice& lattice) {
  TuneColumn c;
  c.estimator = "output";
  c.lambda = 0.2;
  Tallies t;
  for (const auto& [k, n, meeting, peak, overshoot] : cells) {
    std::vector<sim::RunSummary> runs;
    for (int i = 0; i < n; ++i) {
      runs.push_back(i < meeting ? FakeRun({0.02}, 1.0, peak) : FakeRun({overshoot}, 0.5, peak));
    }
    c.rows.push_back(SummarizeDt(lattice.dT(k), runs, d.criterion, d.settings));
    t[k] = {c.rows.back().seeds, c.rows.back().meeting};
    c.runs += n;
  }
  c.window = FindWindow(t, d.settings, lattice);
  c.lower_edge = c.window.found ? EdgeEstimate(c.window.lower, lattice) : std::nan("");
  c.upper_edge = c.window.found ? EdgeEstimate(c.window.upper, lattice) : std::nan("");
  c.recommended = c.window.found ? lattice.dT(c.window.recommended) : std::nan("");
  return c;
}

TEST(TuneReport, SaysWhatLiesBeyondAnEdgeAndWhyNothingMeets) {
  TuneDefinition d;
  const DtLattice lattice(d.settings);
  PreparedSweep p;
  p.task.name = "t";
  TuneOutcome o;
  // Meets at 10-11, marginal at 12 (52/64), meets again at 14: the window ends at the marginal
  // period, and the meeting one beyond it is named.
  o.columns.push_back(Column({{8, 4, 0, 50, 0.02},
                              {10, 64, 64, 50, 0.02},
                              {11, 16, 16, 50, 0.02},
                              {12, 64, 52, 50, 0.02},
                              {14, 64, 64, 50, 0.02},
                              {16, 4, 0, 50, 0.02}},
                             d, lattice));
  // Nothing meets; the closest is marginal (56/64): what would decide it.
  o.columns.push_back(Column({{10, 64, 56, 50, 0.02}, {20, 4, 0, 50, 0.02}}, d, lattice));
  // Every run past its temperature limit (150 of 100 C).
  o.columns.push_back(Column({{10, 4, 4, 150, 0.02}, {20, 4, 4, 150, 0.02}}, d, lattice));
  // No seed meets anywhere: the closest is the period breaking fewest parts (settling alone at
  // 20, against overshoot and settling at 10).
  o.columns.push_back(Column({{10, 4, 0, 50, 0.5}, {20, 4, 0, 50, 0.02}}, d, lattice));
  const std::string md = TuneMarkdown(p, d, o);
  EXPECT_NE(md.find(fmt::format("(marginal at {}, meets at {})", lattice.dT(12), lattice.dT(11))),
            std::string::npos)
      << md;
  EXPECT_NE(md.find(fmt::format("(fails at {}, meets at {})", lattice.dT(8), lattice.dT(10))),
            std::string::npos)
      << md;
  EXPECT_NE(md.find(fmt::format("also meeting outside the window, beyond a period that does not "
                                "(see its row below): {} s (64/64",
                                lattice.dT(14))),
            std::string::npos)
      << md;
  EXPECT_NE(md.find(fmt::format("none: no dT tried meets; closest {} s, 56/64", lattice.dT(10))),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("marginal (undecided at 64 seeds: raise --max-seeds or lower --level): "
                    "settling 8/64"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("none: every run is past a datasheet limit"), std::string::npos) << md;
  EXPECT_NE(
      md.find(fmt::format("closest {} s, 0/4 (0-49 %), fails: settling 4/4 |", lattice.dT(20))),
      std::string::npos)
      << md;
}

}  // namespace file_tune_seed_test
}  // namespace recruit::sweep
