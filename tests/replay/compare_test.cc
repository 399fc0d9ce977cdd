// The comparison (src/replay/compare.h) on synthetic signals with known answers.
#include "replay/compare.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace recruit::replay {
namespace file_compare_test {

TEST(ReplayLag, RecoversAKnownShiftOfASmoothSignal) {
  // b(t) = sin(0.3 t); a(t) = b(t - lag): the parabola through the three best shifts finds a lag
  // between samples to a few percent of dT (closed form of the shift).
  const double dT = 0.5;
  for (double lag : {0.0, 0.8, -1.15, 2.0}) {
    std::vector<double> a, b;
    for (int k = 0; k < 400; ++k) {
      b.push_back(std::sin(0.3 * k * dT));
      a.push_back(std::sin(0.3 * (k * dT - lag)));
    }
    EXPECT_NEAR(Lag(a, b, dT, 2.5), lag, 0.05 * dT) << lag;
  }
}

// S runs and a recorded signal, all the same mean path plus independent noise; `offset` is added
// to the recorded one.
SignalComparison Synthetic(std::mt19937_64& rng, int S, double offset) {
  std::normal_distribution<double> n(0, 1);
  const int len = 200;
  std::vector<double> path(len);
  for (int k = 0; k < len; ++k) path[k] = 10 * std::sin(0.05 * k);
  auto draw = [&] {
    std::vector<double> x(len);
    double walk = 0;  // a slow drift, like the on-count's under the broadcasts
    for (int k = 0; k < len; ++k) {
      walk = 0.95 * walk + 0.3 * n(rng);
      x[k] = path[k] + walk + 0.2 * n(rng);
    }
    return x;
  };
  std::vector<std::vector<double>> runs;
  for (int a = 0; a < S; ++a) runs.push_back(draw());
  std::vector<double> rec = draw();
  for (double& v : rec) v += offset;
  auto c = CompareSignal(rec, runs, 1.0, 5.0, Criterion{});
  EXPECT_TRUE(c.ok());
  return *c;
}

TEST(ReplayCriterion, ExchangeableRecordingIsRarelyFlaggedAndItsRatioIsNearOne) {
  // Monte Carlo: the recording is one more run. The normalised ratio's mean is 1 within 0.05
  // (300 trials), and the bands (ratio 4 or 2.5 and z 4) flag fewer than 1 % of them.
  std::mt19937_64 rng(11);
  double ratio = 0, step = 0;
  int flagged = 0;
  const int trials = 300;
  for (int t = 0; t < trials; ++t) {
    const SignalComparison c = Synthetic(rng, 16, 0.0);
    ratio += c.rmse_ratio / trials;
    step += c.step_ratio / trials;
    flagged += c.flagged;
  }
  EXPECT_NEAR(ratio, 1.0, 0.05);
  EXPECT_NEAR(step, 1.0, 0.05);
  EXPECT_LE(flagged, 3);
}

TEST(ReplayCriterion, AnOffsetOfSixSpreadsIsFlaggedAndMeasuredAsBias) {
  std::mt19937_64 rng(12);
  double bias = 0;
  const int trials = 20;
  for (int t = 0; t < trials; ++t) {
    const SignalComparison c = Synthetic(rng, 16, 6.0);
    EXPECT_TRUE(c.flagged) << c.rmse_ratio << " " << c.rmse_z;
    bias += c.recorded.bias / trials;
  }
  // One trial's bias: the drift's mean over 200 samples (AR(1), stationary sd 0.96, correlation
  // time 20 samples: sd ~0.45); over 20 trials sd ~0.1: within 4 sd.
  EXPECT_NEAR(bias, 6.0, 0.4);
}

TEST(ReplayCriterion, NeedsThreeRunsOfTheLogsLength) {
  EXPECT_FALSE(CompareSignal({1, 2}, {{1, 2}, {1, 2}}, 1, 1, Criterion{}).ok());
  EXPECT_FALSE(CompareSignal({1, 2}, {{1, 2}, {1, 2}, {1}}, 1, 1, Criterion{}).ok());
}

}  // namespace file_compare_test
}  // namespace recruit::replay
