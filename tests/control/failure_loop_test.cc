// The controller with failed units: the law on the estimated working units against a hand
// computation, and closed loops on the isometric bench whose units fail (tests/control/
// failure_loop.h; seeds 1-3 here, the measurement in docs/failures.md uses 100 and up).
#include "tests/control/failure_loop.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "control/recruitment_controller.h"

namespace recruit::control {
namespace file_failure_loop_test {

namespace fl = failure_loop;

// An estimator with fixed counts, to check the law.
class FixedEstimator final : public OnCountEstimator {
 public:
  FixedEstimator(double on, FailureEstimate f) : f(f), on_(on) {}
  void Reset() override {}
  using OnCountEstimator::UpdateWithMeasurement;
  void UpdateWithMeasurement(double y, double) override { measured.push_back(y); }
  void Broadcasted(const Broadcast&) override {}
  double EstimatedOn() const override { return on_; }
  double EstimatedOnVariance() const override { return 1; }
  Eigen::VectorXd StateEstimate() const override { return Eigen::VectorXd::Zero(1); }
  std::vector<std::string> StateNames() const override { return {"x"}; }
  std::vector<bool> OnStates() const override { return {true}; }
  std::optional<FailureEstimate> Failures() const override {
    return counts_failures ? std::optional<FailureEstimate>(f) : std::nullopt;
  }
  bool counts_failures = true;   // false: an estimator that does not count failed units
  FailureEstimate f;             // what Failures() answers (a test may change it between steps)
  std::vector<double> measured;  // the forces it was given

 private:
  double on_;
};

RecruitmentController Make(double on, FailureEstimate f) {
  ControllerParams p;
  p.num_units = 60;
  p.unit_force = 0.5;
  p.lambda = 0.2;
  return RecruitmentController::Create(p, std::make_unique<FixedEstimator>(on, f)).value();
}

TEST(FailureAwareLaw, ActsOnTheWorkingUnitsAndCountsTheStuckOnes) {
  FailureEstimate f;
  f.working = 40, f.open = 15, f.stuck = 5;
  // 20 heated (5 of them stuck), reference 15 N = 30 units: the working units must reach 25,
  // 15 are on, 25 off: p_on = 0.2 (25 - 15) / (40 - 15).
  RecruitmentController c = Make(20, f);
  Broadcast b = c.Step(15.0, 0);
  EXPECT_DOUBLE_EQ(b.p_on, 0.2 * 10 / 25);
  EXPECT_EQ(b.p_off, 0);
  EXPECT_EQ(c.saturation(), 0);
  // 25 N = 50 units > 40 working + 5 stuck: saturated, the law asks for every working unit
  // (target clamped to 40: p_on = 0.2 (40 - 15) / 25), no more.
  b = c.Step(25.0, 0);
  EXPECT_EQ(c.saturation(), 1);
  EXPECT_DOUBLE_EQ(b.p_on, 0.2);
  // 1 N = 2 units < 5 stuck: the stuck units alone exceed it; release every working unit.
  b = c.Step(1.0, 0);
  EXPECT_EQ(c.saturation(), -1);
  EXPECT_DOUBLE_EQ(b.p_off, 0.2);
}

// Without failure counts every unit works: a reference that needs more than all of them is
// out of reach (+1), one they can give is not; never -1 (no stuck units).
TEST(FailureAwareLaw, WithoutFailuresAReferenceBeyondEveryUnitIsOutOfReach) {
  ControllerParams p;
  p.num_units = 60;
  p.unit_force = 0.5;
  p.lambda = 0.2;
  auto est = std::make_unique<FixedEstimator>(20, FailureEstimate{});
  est->counts_failures = false;
  RecruitmentController c = RecruitmentController::Create(p, std::move(est)).value();
  c.Step(29.9, 0);  // 59.8 units
  EXPECT_EQ(c.saturation(), 0);
  c.Step(30.1, 0);  // 60.2 units
  EXPECT_EQ(c.saturation(), 1);
  c.Step(0.0, 0);
  EXPECT_EQ(c.saturation(), 0);
}

// Exploration: a declaration starts `instants` instants of the exploration broadcast, then none
// may start for `rest` instants; the periodic trigger fires every period / dT instants.
TEST(Exploration, StartsOnADeclarationOrPeriodAndRests) {
  FailureEstimate f;
  f.working = 60;
  auto est = std::make_unique<FixedEstimator>(30, f);
  FixedEstimator* e = est.get();
  ControllerParams p;
  p.num_units = 60, p.unit_force = 0.5, p.lambda = 0.2, p.dT = 0.5;
  p.exploration.p_on = 0.3, p.exploration.instants = 2, p.exploration.rest = 3;
  RecruitmentController c = RecruitmentController::Create(p, std::move(est)).value();
  // On target (15 N = 30 units): the law is idle.
  Broadcast b = c.Step(15.0, 0);
  EXPECT_FALSE(c.exploring());
  EXPECT_EQ(b.p_on, 0);
  e->f.declared = true;  // declared: 2 instants of p_on 0.3, p_off 30 x 0.3 / 30
  std::vector<int> explored;
  for (int k = 0; k < 8; ++k) {
    b = c.Step(15.0, 0);
    explored.push_back(c.exploring());
    if (c.exploring()) {
      EXPECT_DOUBLE_EQ(b.p_on, 0.3);
      EXPECT_DOUBLE_EQ(b.p_off, 0.3);
    }
  }
  // Declared at every instant: 2 on, 3 at rest, 2 on, ...
  EXPECT_EQ(explored, (std::vector<int>{1, 1, 0, 0, 0, 1, 1, 0}));
  // Periodic (every 2 s = 4 instants), toggling (not balanced): p_on = p_off = 1.
  e->f.declared = false;
  p.exploration = {};
  p.exploration.p_on = 1, p.exploration.balanced = false, p.exploration.instants = 1;
  p.exploration.period = 2;
  RecruitmentController t =
      RecruitmentController::Create(p, std::make_unique<FixedEstimator>(30, f)).value();
  explored.clear();
  for (int k = 0; k < 9; ++k) {
    b = t.Step(15.0, 0);
    explored.push_back(t.exploring());
    if (t.exploring()) {
      EXPECT_EQ(b.p_off, 1.0);
    }
  }
  EXPECT_EQ(explored, (std::vector<int>{0, 0, 0, 1, 0, 0, 0, 1, 0}));
  // Toggle for 3 instants: switch all at the first, hold (nothing switches) at the other two, and
  // the estimator is not given the force at the 2 instants after the first.
  p.exploration = {};
  p.exploration.p_on = 1, p.exploration.balanced = false, p.exploration.instants = 3;
  p.exploration.unmeasured = 2;
  auto held = std::make_unique<FixedEstimator>(30, f);
  FixedEstimator* h = held.get();
  RecruitmentController u = RecruitmentController::Create(p, std::move(held)).value();
  h->f.declared = true;
  std::vector<Broadcast> sent;
  for (int k = 0; k < 4; ++k) sent.push_back(u.Step(15.0, 1.0 + k));
  EXPECT_EQ(sent[0].p_on, 1.0);
  EXPECT_EQ(sent[0].p_off, 1.0);
  for (int k : {1, 2}) {
    EXPECT_EQ(sent[k].p_on, 0.0);
    EXPECT_EQ(sent[k].p_off, 0.0);
    EXPECT_TRUE(std::isnan(h->measured[k]));
  }
  EXPECT_EQ(h->measured[0], 1.0);
  EXPECT_EQ(h->measured[3], 4.0);
  p.exploration.unmeasured = 4;  // more than its instants
  EXPECT_FALSE(p.Validate());
  p.exploration.instants = 0;
  EXPECT_FALSE(p.Validate());
}

// Fatigue: with an estimated force scale c each working unit pulls c of a fresh one, so the law
// targets (reference / unit force - stuck) / c working units.
TEST(FailureAwareLaw, DividesTheWorkingTargetByTheForceScale) {
  FailureEstimate f;
  f.working = 60, f.force_scale = 0.8;
  // 15 N = 30 fresh units = 37.5 units at 0.8; 30 on, 30 off: p_on = 0.2 (37.5 - 30) / 30.
  RecruitmentController c = Make(30, f);
  const Broadcast b = c.Step(15.0, 0);
  EXPECT_DOUBLE_EQ(b.p_on, 0.2 * 7.5 / 30);
  EXPECT_EQ(c.saturation(), 0);
  // 25 N = 50 fresh units = 62.5 at 0.8 > 60 working: out of reach.
  c.Step(25.0, 0);
  EXPECT_EQ(c.saturation(), 1);
}

fl::Spec Bench(const char* config, std::uint64_t seed, double duration,
               std::function<double(double)> ref, const char* kind = "kalman-failures") {
  return {config, *EstimatorSpec::Parse(kind), 0.5, 0.2, seed, duration, std::move(ref), {}};
}

// Losing 10 % or 30 % of the units at 60 s with 15 N held (reachable by the rest): 20-40 s
// later the tracking error is back at the level of the same seed without the loss.
TEST(FailureLoop, TrackingRecoversAfterLosingTenOrThirtyPercent) {
  auto ref = [](double) { return 15.0; };
  for (const char* loss : {"failures=60:6:open", "failures=60:18:open", "failures=60:6:stuck"}) {
    for (std::uint64_t seed : {1, 2}) {
      const auto with = fl::Run(Bench(loss, seed, 100, ref));
      const auto without = fl::Run(Bench("", seed, 100, ref));
      ASSERT_TRUE(with.ok() && without.ok());
      EXPECT_EQ(fl::DeclarationsBefore(*with, 60), 0);
      const double after = fl::MeanError(*with, 80, 100);
      const double level =
          std::max(fl::MeanError(*without, 40, 60), fl::MeanError(*without, 80, 100));
      EXPECT_LT(after, level + 0.15) << loss << " seed " << seed;
      EXPECT_GT(fl::MeanNees(*with), 0.3) << loss;
    }
  }
}

// 30 % lost, then a reference beyond the 42 working units (22 N > 42 x 0.45 N) for 60 s: the
// controller says it is saturated; back within reach, the error returns to its level.
TEST(FailureLoop, OutOfReachSaturatesAndRecoversWithoutWindUp) {
  for (std::uint64_t seed : {1, 3}) {
    const auto run = fl::Run(Bench("failures=60:18:open", seed, 180,
                                   [](double t) { return t >= 70 && t < 130 ? 22.0 : 15.0; }));
    const auto base = fl::Run(Bench("", seed, 180, [](double) { return 15.0; }));
    ASSERT_TRUE(run.ok() && base.ok());
    int saturated = 0, n = 0;
    for (const auto& r : *run) {
      if (r.t >= 80 && r.t < 130) saturated += r.saturation == 1, ++n;
      if (r.t >= 150) {
        EXPECT_EQ(r.saturation, 0) << r.t;
      }
    }
    EXPECT_GE(saturated, 0.9 * n) << "seed " << seed;
    EXPECT_LT(fl::MeanError(*run, 150, 180), fl::MeanError(*base, 150, 180) + 0.15);
  }
}

// Stuck units above a low reference: flagged (-1), and every working unit is released.
TEST(FailureLoop, StuckUnitsAboveTheReferenceAreFlagged) {
  const auto run = fl::Run(Bench("failures=20:8:stuck", 2, 60, [](double) { return 1.5; }));
  ASSERT_TRUE(run.ok());
  const fl::Instant& last = run->back();
  EXPECT_EQ(last.stuck, 8);
  EXPECT_EQ(last.saturation, -1);
  EXPECT_EQ(last.on, 8);  // only the stuck units are heated
}

// The census: asked every census_period (rounded to whole instants) after broadcasting, and
// refused without a failure-aware estimator.
TEST(Census, AskedEveryPeriodAndOnlyWithAFailureAwareEstimator) {
  ControllerParams p;
  p.num_units = 60;
  p.unit_force = 0.45;
  p.dT = 0.5;
  p.census_period = 2.4;  // 5 instants
  auto c = RecruitmentController::Create(p, *EstimatorSpec::Parse("kalman-failures"));
  ASSERT_TRUE(c.ok()) << c.error();
  std::vector<int> asked;
  for (int k = 0; k < 16; ++k) {
    c->Step(10, 0);
    if (c->census()) asked.push_back(k);
  }
  EXPECT_EQ(asked, (std::vector<int>{4, 9, 14}));
  auto plain = RecruitmentController::Create(p, *EstimatorSpec::Parse("kalman-augmented"));
  ASSERT_FALSE(plain.ok());
  EXPECT_NE(plain.error().find("census_period = 2.4"), std::string::npos) << plain.error();
  EXPECT_NE(plain.error().find("kalman-failures"), std::string::npos) << plain.error();
  p.census_period = -1;
  EXPECT_FALSE(p.Validate().ok());
}

// Census keys in the plant without a census: every recorded value of the closed loop is that
// of the plant without them.
TEST(FailureLoop, CensusKeysWithoutACensusChangeNothing) {
  auto ref = [](double t) { return t < 30 ? 12.0 : 18.0; };
  const auto a = fl::Run(Bench("failures=20:6:open", 2, 60, ref));
  const auto b = fl::Run(Bench("failures=20:6:open census_noise=0.01", 2, 60, ref));
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a->size(), b->size());
  for (size_t i = 0; i < a->size(); ++i) {
    const fl::Instant &x = (*a)[i], &y = (*b)[i];
    ASSERT_EQ(x.force, y.force) << x.t;
    ASSERT_EQ(x.est_on, y.est_on) << x.t;
    ASSERT_EQ(x.est_on_var, y.est_on_var) << x.t;
    ASSERT_EQ(x.est_working, y.est_working) << x.t;
    ASSERT_EQ(x.on, y.on) << x.t;
  }
}

// With a census every 5 instants (2.5 s), losses of 10 % and 30 % open and 10 % stuck at 60 s
// (right after a census: the worst phase) are counted within 2 units within 5 instants, and a
// run without loss declares nothing.
TEST(FailureLoop, ACensusEveryFiveInstantsFindsEveryLossWithinFive) {
  auto ref = [](double) { return 15.0; };
  for (const char* loss :
       {"failures=60:6:open", "failures=60:18:open", "failures=60:6:stuck", ""}) {
    for (std::uint64_t seed : {1, 2, 3}) {
      fl::Spec spec = Bench(loss, seed, 80, ref);
      spec.census_period = 2.5;
      const auto run = fl::Run(spec);
      ASSERT_TRUE(run.ok()) << run.error();
      EXPECT_EQ(fl::DeclarationsBefore(*run, 60), 0) << loss << " seed " << seed;
      if (*loss == 0) {
        EXPECT_EQ(fl::DeclarationsBefore(*run, 1e9), 0) << "seed " << seed;
        continue;
      }
      const int k = fl::InstantsToFind(*run, 60);
      EXPECT_GE(k, 0) << loss << " seed " << seed;
      EXPECT_LE(k, 5) << loss << " seed " << seed;
      EXPECT_NEAR(run->back().est_working, run->back().working, 0.5) << loss << " seed " << seed;
    }
  }
}

// A census every instant that ends at the instant: a loss within a control period (60.25 s) is
// counted at the next instant, and the on count's NEES over the whole run stays in [0.3, 2]
// even for 30 % lost (the census gives the count; the covariance carries which units they were).
TEST(FailureLoop, ACensusEndingAtEveryInstantKeepsTheWholeRunHonest) {
  auto ref = [](double) { return 15.0; };
  for (const char* loss : {"failures=60.25:6:open", "failures=60.25:18:open"}) {
    for (std::uint64_t seed : {1, 2, 3}) {
      fl::Spec spec = Bench(loss, seed, 100, ref);
      spec.census_period = 0.5;
      spec.census_at_end = true;
      const auto run = fl::Run(spec);
      ASSERT_TRUE(run.ok()) << run.error();
      EXPECT_EQ(fl::InstantsToFind(*run, 60), 0) << loss << " seed " << seed;
      EXPECT_GE(fl::MeanNees(*run), 0.3) << loss << " seed " << seed;
      EXPECT_LE(fl::MeanNees(*run), 2) << loss << " seed " << seed;
      EXPECT_EQ(fl::DeclarationsBefore(*run, 60), 0) << loss << " seed " << seed;
    }
  }
}

}  // namespace file_failure_loop_test
}  // namespace recruit::control
