// The controller on the isometric bench (models/isometric_bench.xml, 60 units, through the SMA
// plugin's host API), with a minimal loop written here: every dT sample the force, Step the
// controller, broadcast, advance the physics. A 15 N step reference from rest, 60 s.
// References: the paper's Sec. V results (dT = 0.5 s: output-only counting over-recruits, the
// filter on the identified transient model converges) and the plugin's ground-truth on-count.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "control/recruitment_controller.h"
#include "plugin/sma_host.h"

namespace recruit::control {
namespace file_closed_loop_bench_test {

struct LoopResult {
  double max_force = 0;   // N
  double late_error = 0;  // mean |force - reference| over the last 20 s, N
  double count_rmse = 0;  // estimated vs true on-count at the control instants, units
  int max_on = 0;         // largest true on-count
  double target_on = 0;   // reference / settled unit force
};

LoopResult RunBench(const EstimatorSpec& spec, double dT, double lambda, std::uint64_t seed,
                    double reference = 15.0, double duration = 60.0) {
  LoopResult r;
  char err[1000] = "";
  std::unique_ptr<mjModel, void (*)(mjModel*)> m(
      mj_loadXML(RECRUIT_SOURCE_DIR "/models/isometric_bench.xml", nullptr, err, sizeof err),
      mj_deleteModel);
  EXPECT_TRUE(m) << err;
  if (!m) return r;
  auto plugin = sma::SmaHost::Create(m.get());
  EXPECT_TRUE(plugin.ok()) << plugin.error();
  if (!plugin.ok()) return r;
  const sma::SmaHost& p = **plugin;
  std::unique_ptr<mjData, void (*)(mjData*)> d(mj_makeData(m.get()), mj_deleteData);
  p.Reset(d.get(), seed);
  mj_forward(m.get(), d.get());
  ControllerParams params;
  params.num_units = p.num_units(0);
  params.unit_force = p.SettledUnitForce(0);
  params.dT = dT;
  params.lambda = lambda;
  auto c = RecruitmentController::Create(params, spec);
  EXPECT_TRUE(c.ok()) << c.error();
  if (!c.ok()) return r;
  r.target_on = reference / params.unit_force;
  const int steps = static_cast<int>(std::lround(dT / m->opt.timestep));
  const int instants = static_cast<int>(std::lround(duration / dT));
  const int late_from = static_cast<int>(std::lround((duration - 20) / dT));
  double sq = 0;
  for (int k = 0; k < instants; ++k) {
    const double force = p.Force(d.get(), 0);
    const int on = p.OnCount(d.get(), 0);
    const Broadcast b = c->Step(reference, force);
    sq += std::pow(c->estimated_on() - on, 2);
    r.max_force = std::max(r.max_force, force);
    r.max_on = std::max(r.max_on, on);
    if (k >= late_from) r.late_error += std::abs(force - reference) / (instants - late_from);
    EXPECT_TRUE(p.Broadcast(d.get(), 0, b.p_on, b.p_off).ok());
    for (int i = 0; i < steps; ++i) mj_step(m.get(), d.get());
  }
  r.count_rmse = std::sqrt(sq / instants);
  // The figures docs/controller.md quotes.
  std::printf(
      "  %-16s %-12s dT %.1f lambda %.1f seed %llu: max force %.2f N (ref %.1f), max on %d "
      "(target %.1f), late |err| %.3f N, on-count RMSE %.2f\n",
      EstimatorKindName(spec.kind), ToString(spec.covariance), dT, lambda,
      static_cast<unsigned long long>(seed), r.max_force, reference, r.max_on, r.target_on,
      r.late_error, r.count_rmse);
  return r;
}

EstimatorSpec Spec(const std::string& kind, const std::string& covariance = "extended") {
  auto s = EstimatorSpec::Parse(kind, covariance);
  EXPECT_TRUE(s.ok()) << s.error();
  return *s;
}

TEST(ClosedLoopBench, AugmentedFilterConvergesAtHalfSecondForLambdasUpToOne) {
  // The shipped model models/identified/bench_n60_dt0.5_m20.json, extended covariance.
  for (double lambda : {0.2, 0.5, 1.0}) {
    const LoopResult r = RunBench(Spec("kalman-augmented"), 0.5, lambda, 1);
    // Within 1.5 units' force (0.7 N) of the reference over the last 20 s (the target, 33.1
    // units, is not a whole number, so the count dithers), no more than 10 % overshoot, and the
    // filter's on-count within about one unit of the truth on average. (The datasheet unit's
    // force rises as a delayed ramp, docs/sma-units.md: at lambda 0.5 the random recruitment
    // overshoots the count by 3-4 units, 7-8 % of the force, with the count estimate right.)
    EXPECT_LT(r.late_error, 0.7) << "lambda " << lambda;
    EXPECT_LT(r.max_force, 1.10 * 15.0) << "lambda " << lambda;
    EXPECT_LT(r.count_rmse, 1.5) << "lambda " << lambda;
    EXPECT_LE(r.max_on, std::ceil(r.target_on) + 4) << "lambda " << lambda;
  }
}

TEST(ClosedLoopBench, AugmentedFilterConvergesInTheConservativeMode) {
  const LoopResult r = RunBench(Spec("kalman-augmented", "conservative"), 0.5, 0.5, 2);
  EXPECT_LT(r.late_error, 0.7);
  EXPECT_LT(r.max_force, 1.08 * 15.0);
  EXPECT_LT(r.count_rmse, 1.5);
}

TEST(ClosedLoopBench, PlainModeWithoutQzLosesTheCount) {
  // Without the transition covariance Qz (eq. 25) the filter's P collapses, it stops listening
  // to the force and its count drifts from the truth (the paper's reason for Qz).
  double plain_sum = 0, extended_sum = 0;
  for (std::uint64_t seed : {1, 2, 3}) {
    const LoopResult plain = RunBench(Spec("kalman-augmented", "plain"), 0.5, 0.5, seed);
    const LoopResult ext = RunBench(Spec("kalman-augmented", "extended"), 0.5, 0.5, seed);
    EXPECT_GT(plain.count_rmse, ext.count_rmse) << "seed " << seed;
    plain_sum += plain.count_rmse;
    extended_sum += ext.count_rmse;
  }
  EXPECT_GT(plain_sum, 3 * extended_sum);
}

TEST(ClosedLoopBench, OutputOnlyCountingOverRecruitsAtHalfSecond) {
  // The paper's failure: a unit just switched on shows a fraction of its settled force, so the
  // force-only count lags the true count and the law keeps recruiting. Same seeds, same gain:
  // the output-only loop recruits far beyond the target and overshoots the force; the filter on
  // the transient model does not.
  for (std::uint64_t seed : {1, 2, 3}) {
    const LoopResult out = RunBench(Spec("output"), 0.5, 0.5, seed);
    const LoopResult kf = RunBench(Spec("kalman-augmented"), 0.5, 0.5, seed);
    EXPECT_GT(out.max_force, 1.10 * 15.0) << "seed " << seed;
    EXPECT_GT(out.max_on, out.target_on + 8) << "seed " << seed;
    EXPECT_GT(out.count_rmse, 3.0) << "seed " << seed;
    EXPECT_LT(kf.max_force, 1.10 * 15.0) << "seed " << seed;
    // The filter's overshoot is less than half the output-only loop's.
    EXPECT_LT(kf.max_force - 15.0, 0.5 * (out.max_force - 15.0)) << "seed " << seed;
    EXPECT_LT(kf.count_rmse, out.count_rmse / 2) << "seed " << seed;
  }
}

TEST(ClosedLoopBench, OutputOnlyCountingIsSmoothAtTwoSeconds) {
  // dT = 2.0 s, lambda = 0.2 (the paper's Fig. 5 setting that works): units settle within a
  // period, so the force-only count is right and the loop does not overshoot.
  const LoopResult r = RunBench(Spec("output"), 2.0, 0.2, 1, 15.0, 120.0);
  EXPECT_LT(r.max_force, 1.03 * 15.0);
  EXPECT_LT(r.late_error, 0.45);
}

}  // namespace file_closed_loop_bench_test
}  // namespace recruit::control
