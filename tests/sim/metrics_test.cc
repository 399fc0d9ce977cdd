// Metrics against closed forms on synthetic signals.
#include "sim/metrics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "common/rng.h"
#include "sim/metrics_stream.h"

namespace recruit::sim {
namespace file_metrics_test {

std::vector<double> Times(double dt, double T) {
  std::vector<double> t;
  for (long k = 0; k * dt < T - 1e-12; ++k) t.push_back(k * dt);
  return t;
}

TEST(Metrics, RmseOfConstantOffsetIsTheOffset) {
  std::vector<double> r(100, 3.0), y(100, 3.5);
  EXPECT_DOUBLE_EQ(TrackingRmse(r, y), 0.5);
}

TEST(Metrics, RmseOfSineErrorIsAmplitudeOverRootTwo) {
  // Over whole periods, mean sin^2 = 1/2.
  const auto t = Times(1e-3, 10.0);
  std::vector<double> r(t.size(), 0.0), y;
  for (double x : t) y.push_back(2.0 * std::sin(2 * M_PI * x));
  EXPECT_NEAR(TrackingRmse(r, y), 2.0 / std::sqrt(2.0), 1e-9);
}

TEST(Metrics, IaeOfExponentialErrorIsItsIntegral) {
  // e(t) = exp(-t / tau): integral over [0, T) = tau (1 - exp(-T / tau)).
  const double dt = 1e-4, T = 5, tau = 0.7;
  const auto t = Times(dt, T);
  std::vector<double> r(t.size(), 1.0), y;
  for (double x : t) y.push_back(1.0 - std::exp(-x / tau));
  const double exact = tau * (1 - std::exp(-T / tau));
  // Rectangle rule with left samples overestimates by about e(0) dt / 2.
  EXPECT_NEAR(IntegralAbsoluteError(t, r, y, T), exact, dt);
}

// A second-order underdamped step response: y = 1 - exp(-z w t) (cos(wd t) + z/sqrt(1-z^2)
// sin(wd t)). Overshoot exp(-pi z / sqrt(1 - z^2)); the last exit from a band b is at an
// extremum or a crossing we locate by brute force on a finer grid.
TEST(Metrics, SecondOrderStepOvershootMatchesClosedForm) {
  const double z = 0.3, w = 2.0, wd = w * std::sqrt(1 - z * z), dt = 1e-4;
  const auto t = Times(dt, 30.0);
  std::vector<double> y;
  for (double x : t) {
    y.push_back(1 - std::exp(-z * w * x) *
                        (std::cos(wd * x) + z / std::sqrt(1 - z * z) * std::sin(wd * x)));
  }
  const ReferenceStep step{0.0, 0.0, 1.0, 30.0};
  const auto resp = StepResponses(t, y, {step}, 0.1);
  ASSERT_EQ(resp.size(), 1u);
  EXPECT_NEAR(resp[0].overshoot, std::exp(-M_PI * z / std::sqrt(1 - z * z)), 1e-6);
  EXPECT_TRUE(resp[0].settled);
  // The envelope bound exp(-z w t) / sqrt(1 - z^2) = 0.1 gives an upper bound on settling time;
  // the true last exit lies within half a period below it.
  const double envelope = -std::log(0.1 * std::sqrt(1 - z * z)) / (z * w);
  EXPECT_LE(resp[0].settling_time, envelope + dt);
  EXPECT_GE(resp[0].settling_time, envelope - M_PI / wd);
}

TEST(Metrics, FirstOrderStepSettlesAtTauLnTenWithoutOvershoot) {
  // y = 20 - 10 exp(-t / tau) for a step 10 -> 20 at t = 2: within 10 % after tau ln 10.
  const double tau = 1.5, dt = 1e-3;
  const auto t = Times(dt, 20.0);
  std::vector<double> y;
  for (double x : t) y.push_back(x < 2 ? 10.0 : 20 - 10 * std::exp(-(x - 2) / tau));
  const auto resp = StepResponses(t, y, {{2.0, 10.0, 20.0, 20.0}}, 0.1);
  ASSERT_EQ(resp.size(), 1u);
  EXPECT_DOUBLE_EQ(resp[0].overshoot, 0.0);
  EXPECT_NEAR(resp[0].settling_time, tau * std::log(10.0), 2 * dt);
  EXPECT_TRUE(resp[0].settled);
}

TEST(Metrics, DownwardStepOvershootCountsExcursionBelowTarget) {
  // 30 -> 10, undershooting to 7: overshoot 3 / 20 = 0.15, never back in the band: unsettled.
  std::vector<double> t{0, 1, 2, 3, 4}, y{30, 20, 7, 7, 7};
  const auto resp = StepResponses(t, y, {{0.0, 30.0, 10.0, 5.0}}, 0.1);
  ASSERT_EQ(resp.size(), 1u);
  EXPECT_DOUBLE_EQ(resp[0].overshoot, 0.15);
  EXPECT_FALSE(resp[0].settled);
  EXPECT_DOUBLE_EQ(resp[0].settling_time, 5.0);
}

TEST(Metrics, ExcessTotalVariationCountsExtraSwings) {
  // Reference: one step of 1. Response: rises to 1, then one full swing of amplitude 0.2 (up
  // 0.2, down 0.4, up 0.2): extra variation 0.8 -> 0.8 / 1.
  std::vector<double> r{0, 1, 1, 1, 1, 1}, y{0, 1, 1.2, 0.8, 1.0, 1.0};
  EXPECT_NEAR(ExcessTotalVariation(r, y), 0.8, 1e-12);
  // A monotone response has none.
  std::vector<double> y2{0, 0.5, 0.9, 1.0, 1.0, 1.0};
  EXPECT_NEAR(ExcessTotalVariation(r, y2), 0.0, 1e-12);
}

TEST(Metrics, ExcessTotalVariationOfSineAroundConstantIsFourAmplitudesPerPeriod) {
  const auto t = Times(1e-4, 3.0);  // three periods of 1 s
  std::vector<double> r(t.size(), 5.0), y;
  for (double x : t) y.push_back(5.0 + 0.5 * std::sin(2 * M_PI * x));
  EXPECT_NEAR(ExcessTotalVariation(r, y), 3 * 4 * 0.5, 1e-3);
}

TEST(Metrics, SwitchingRateIsTransitionsPerUnitPerSecond) {
  // 10 units over 5 s: +4, -2, +3 = 9 transitions -> 9 / (10 * 5).
  std::vector<int> on{0, 4, 4, 2, 5};
  EXPECT_DOUBLE_EQ(SwitchingRate(on, 10, 5.0), 9.0 / 50.0);
}

TEST(Metrics, EstimatorScoreRmseNeesAndWithinThree) {
  std::vector<double> est{10, 12, 20, 30}, truth{10, 10, 16, 30}, var{1, 4, 4, 0};
  const EstimatorScore s = ScoreEstimator(est, truth, var);
  EXPECT_EQ(s.samples, 4);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt((0 + 4 + 16 + 0) / 4.0));
  // NEES over samples with var > 0: 0/1, 4/4, 16/4 -> mean 5/3.
  EXPECT_DOUBLE_EQ(s.mean_nees, (0 + 1 + 4) / 3.0);
  EXPECT_DOUBLE_EQ(s.within3, 3.0 / 4.0);
  EXPECT_DOUBLE_EQ(s.within_band, 3.0 / 4.0);  // the default band is 3 units
  // A band of 5 % of 100 units: the error of 4 is inside it too.
  EXPECT_DOUBLE_EQ(ScoreEstimator(est, truth, var, 5).within_band, 1.0);
}

TEST(Metrics, NeesOfGaussianErrorsWithTrueVarianceIsNearOne) {
  // Deterministic normal quantiles as errors: the sample mean of e^2 / s^2 is ~1.
  std::vector<double> est, truth, var;
  const int n = 2000;
  for (int i = 0; i < n; ++i) {
    const double p = (i + 0.5) / n;
    // Inverse normal CDF by bisection on erfc.
    double lo = -10, hi = 10;
    for (int it = 0; it < 100; ++it) {
      const double mid = 0.5 * (lo + hi);
      (0.5 * std::erfc(-mid / std::sqrt(2.0)) < p ? lo : hi) = mid;
    }
    est.push_back(3.0 * lo);
    truth.push_back(0);
    var.push_back(9.0);
  }
  EXPECT_NEAR(ScoreEstimator(est, truth, var).mean_nees, 1.0, 0.01);
}

// Windows in any arrangement: steps' windows that overlap, nest, hold no sample, open before the
// first sample or after the last, and disturbance windows across them. The stream against the
// pure StepResponses and the disturbances' definition (the largest and the last |y - r| of the
// samples in [start, end)), to the bit; a copy made halfway goes on as the original does.
TEST(MetricsStream, WindowsInAnyArrangementEqualThePureFunctions) {
  Rng rng(7);
  auto uniform = [&rng](double lo, double hi) { return lo + (hi - lo) * rng.Uniform(); };
  for (int trial = 0; trial < 60; ++trial) {
    std::vector<ReferenceStep> steps;
    for (int k = 0, n = 1 + static_cast<int>(6 * rng.Uniform()); k < n; ++k) {
      const double time = std::round(uniform(-1, 13)), from = uniform(-2, 2);
      const double to = rng.Uniform() < 0.15 ? from : uniform(-2, 2);       // some of size 0
      steps.push_back({time, from, to, time + std::round(uniform(0, 6))});  // some empty
    }
    std::vector<DisturbanceWindow> pushes;
    for (int k = 0, n = static_cast<int>(4 * rng.Uniform()); k < n; ++k) {
      const double start = std::round(uniform(0, 12));
      pushes.push_back({start, start + std::round(uniform(0, 5))});
    }
    SignalMetrics stream(steps, 0.1, pushes);
    std::vector<SignalMetrics> copy;
    std::vector<double> t, r, y;
    const double h = 0.01 + 0.02 * rng.Uniform();
    double time = 0;
    for (int k = 0; time < 12; ++k, time += h) {
      const double ref = std::sin(0.7 * time),
                   meas = ref + 0.3 * std::sin(3 * time) * uniform(0, 1);
      t.push_back(time), r.push_back(ref), y.push_back(meas);
      stream.Add(time, ref, meas);
      if (k == 300) copy.push_back(stream);
      if (k > 300) copy[0].Add(time, ref, meas);
    }
    ASSERT_EQ(copy.size(), 1u);
    const auto want = StepResponses(t, y, steps, 0.1);
    for (const SignalMetrics* m : {&stream, &copy[0]}) {
      const auto got = m->StepResponses();
      ASSERT_EQ(got.size(), want.size()) << "trial " << trial;
      for (size_t i = 0; i < got.size(); ++i) {
        EXPECT_EQ(got[i].overshoot, want[i].overshoot) << "trial " << trial << " step " << i;
        EXPECT_EQ(got[i].settling_time, want[i].settling_time) << "trial " << trial;
        EXPECT_EQ(got[i].settled, want[i].settled) << "trial " << trial;
      }
      const auto d = m->DisturbanceResponses();
      ASSERT_EQ(d.size(), pushes.size());
      for (size_t i = 0; i < d.size(); ++i) {
        double peak = 0, final = 0;
        for (size_t k = 0; k < t.size(); ++k) {
          if (t[k] < pushes[i].start || t[k] >= pushes[i].end) continue;
          peak = std::max(peak, std::abs(y[k] - r[k]));
          final = std::abs(y[k] - r[k]);
        }
        EXPECT_EQ(d[i].peak_deviation, peak) << "trial " << trial << " push " << i;
        EXPECT_EQ(d[i].final_deviation, final) << "trial " << trial << " push " << i;
      }
      EXPECT_EQ(m->TrackingRmse(), TrackingRmse(r, y));
    }
  }
}

}  // namespace file_metrics_test
}  // namespace recruit::sim

namespace recruit::sim {
namespace file_metrics_test {

// The streaming accumulators against the pure functions on the same signals, to the bit: noisy
// step responses that ring through the band (so settling is decided late), a step with no
// samples, a zero-size step, and estimator samples with NaN estimates and zero variances.
TEST(MetricsStream, AccumulatorsEqualThePureFunctionsExactly) {
  Rng rng(42);
  for (int trial = 0; trial < 20; ++trial) {
    const double h = 0.01 + 0.01 * rng.Uniform();
    std::vector<ReferenceStep> steps = {{1.0, 0.0, 2.0, 6.0},
                                        {6.0, 2.0, 0.5, 11.0},
                                        {11.0, 0.5, 0.5, 14.0},
                                        {30.0, 0.5, 1.0, 31.0}};  // after the end: no samples
    std::vector<double> t, r, y;
    SignalMetrics stream(steps, 0.1);
    double state = 0, vel = 0;
    for (double time = 0; time < 14.0; time += h) {
      double ref = 0;
      for (const auto& s : steps) ref = time >= s.time ? s.to : ref;
      vel += h * (40 * (ref - state) - (2 + 4 * rng.Uniform()) * vel);
      state += h * vel;
      const double meas = state + 0.05 * (rng.Uniform() - 0.5);
      t.push_back(time), r.push_back(ref), y.push_back(meas);
      stream.Add(time, ref, meas);
    }
    EXPECT_EQ(stream.TrackingRmse(), TrackingRmse(r, y));
    EXPECT_EQ(stream.IntegralAbsoluteError(14.0), IntegralAbsoluteError(t, r, y, 14.0));
    EXPECT_EQ(stream.ExcessTotalVariation(), ExcessTotalVariation(r, y));
    const auto a = stream.StepResponses(), b = StepResponses(t, y, steps, 0.1);
    ASSERT_EQ(a.size(), b.size());
    ASSERT_EQ(a.size(), 2u);
    for (size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].overshoot, b[i].overshoot);
      EXPECT_EQ(a[i].settling_time, b[i].settling_time);
      EXPECT_EQ(a[i].settled, b[i].settled);
      EXPECT_EQ(a[i].step.time, b[i].step.time);
    }
  }
  EstimatorScoreAccumulator acc(1.5);
  SwitchingCounter sw;
  std::vector<double> est, truth, var;
  std::vector<int> on;
  for (int k = 0; k < 500; ++k) {
    const double n = std::floor(60 * rng.Uniform());
    const double e = k % 97 == 0 ? std::nan("") : n + 4 * (rng.Uniform() - 0.5);
    const double v = k % 13 == 0 ? 0.0 : rng.Uniform();
    est.push_back(e), truth.push_back(n), var.push_back(v), on.push_back(static_cast<int>(n));
    acc.Add(e, n, v);
    sw.Add(static_cast<int>(n));
  }
  const EstimatorScore a = acc.Score(), b = ScoreEstimator(est, truth, var, 1.5);
  EXPECT_EQ(a.rmse, b.rmse);
  EXPECT_EQ(a.mean_nees, b.mean_nees);
  EXPECT_EQ(a.within3, b.within3);
  EXPECT_EQ(a.within_band, b.within_band);
  EXPECT_EQ(a.samples, b.samples);
  EXPECT_EQ(sw.Rate(60, 250.0), SwitchingRate(on, 60, 250.0));
}

}  // namespace file_metrics_test
// A push inside a step's hold ends the step's scored window there; the push is scored from its
// start to the next event. A first-order step (tau 1 s) with a push at t = 10 that deflects it by
// 0.3 exp(-(t - 10)) afterwards: the step settles (no overshoot, tau ln 10), and the push's peak
// and final deviations are the deflection's closed form at the window's first and last samples.
TEST(MetricsStream, PushesEndTheStepWindowAndAreScoredOnTheirOwn) {
  const std::vector<ReferenceStep> steps = {{1, 0, 1, 30}};
  const auto cut = StepsUntilDisturbances(steps, {10, 40});
  ASSERT_EQ(cut.size(), 1u);
  EXPECT_EQ(cut[0].end, 10);
  const auto windows = DisturbanceWindows({25, 10}, steps, 30);
  ASSERT_EQ(windows.size(), 2u);
  EXPECT_EQ(windows[0].start, 10);
  EXPECT_EQ(windows[0].end, 25);
  EXPECT_EQ(windows[1].end, 30);
  SignalMetrics sig(cut, 0.1, DisturbanceWindows({10}, steps, 30));
  const double h = 0.001;
  double last = 0;
  for (int k = 0; k < 30000; ++k) {
    const double t = k * h;
    const double r = t >= 1 ? 1.0 : 0.0;
    double y = t >= 1 ? 1 - std::exp(-(t - 1)) : 0.0;
    if (t >= 10) y -= 0.3 * std::exp(-(t - 10));
    sig.Add(t, r, y);
    last = std::abs(y - r);
  }
  const auto st = sig.StepResponses();
  ASSERT_EQ(st.size(), 1u);
  EXPECT_TRUE(st[0].settled);
  EXPECT_EQ(st[0].overshoot, 0);
  EXPECT_NEAR(st[0].settling_time, std::log(10.0), 2 * h);
  const auto d = sig.DisturbanceResponses();
  ASSERT_EQ(d.size(), 1u);
  EXPECT_NEAR(d[0].peak_deviation, 0.3 + std::exp(-9.0), 1e-12);
  EXPECT_NEAR(d[0].final_deviation, last, 1e-15);
}

}  // namespace recruit::sim
