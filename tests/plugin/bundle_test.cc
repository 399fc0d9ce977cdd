// The bundle's cohort bookkeeping against a plain per-unit simulation (one UnitState per unit,
// the same random draws), and the broadcast statistics against the binomial law.
#include "plugin/bundle.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "common/rng.h"

namespace recruit::sma {
namespace {

SmaBundle MakeBundle(int units, double merge_t, double merge_xi) {
  auto c = BundleConfig::FromText("b", "units=" + std::to_string(units));
  EXPECT_TRUE(c.ok()) << c.error();
  c->merge_temperature = merge_t;
  c->merge_xi = merge_xi;
  auto b = SmaBundle::Create(*c, 1e-3);
  EXPECT_TRUE(b.ok()) << b.error();
  return b.value();
}

// Reference: every unit simulated on its own, drawing from the same stream in unit order.
struct PerUnit {
  const UnitModel* m;
  std::vector<UnitState> s;
  std::vector<bool> on;
  Rng rng;
  PerUnit(const UnitModel& model, int n, std::uint64_t seed, double stretch)
      : m(&model), s(n, RestState(model, stretch)), on(n, false), rng(seed) {}
  void Broadcast(double p_on, double p_off) {
    for (size_t i = 0; i < s.size(); ++i) {
      const double u = rng.Uniform();
      if (u < (on[i] ? p_off : p_on)) on[i] = !on[i];
    }
  }
  void Advance(double stretch, double dt) {
    for (size_t i = 0; i < s.size(); ++i) AdvanceUnit(*m, s[i], on[i], stretch, dt);
  }
  double Tension(double stretch) const {
    double f = 0;
    for (const auto& u : s) f += m->Tension(u.xi, stretch);
    return f;
  }
};

void RunAgainstReference(int units, double merge_t, double merge_xi, double tol_force,
                         double tol_unit) {
  const SmaBundle b = MakeBundle(units, merge_t, merge_xi);
  const double stretch = b.config().unit.prestretch;
  std::vector<double> state(b.state_size());
  b.Reset(state.data(), 42, stretch);
  PerUnit ref(b.unit(), units, 42, stretch);
  Rng control(7);
  int max_cohorts = 0;
  for (int step = 0; step < 20000; ++step) {
    if (step % 500 == 0) {
      const double p_on = 0.3 * control.Uniform(), p_off = 0.3 * control.Uniform();
      ASSERT_TRUE(b.Broadcast(state.data(), p_on, p_off, stretch).ok());
      ref.Broadcast(p_on, p_off);
    }
    b.Advance(state.data(), stretch, 1e-3);
    ref.Advance(stretch, 1e-3);
    max_cohorts = std::max(max_cohorts, b.NumCohorts(state.data()));
    if (step % 997 == 0) {
      ASSERT_NEAR(b.Tension(state.data(), stretch), ref.Tension(stretch), tol_force)
          << "step " << step;
      int on = 0;
      for (int i = 0; i < units; ++i) {
        ASSERT_EQ(b.UnitOn(state.data(), i), ref.on[i]) << "unit " << i;
        ASSERT_NEAR(b.UnitTemperature(state.data(), i), ref.s[i].temperature, tol_unit);
        ASSERT_NEAR(b.UnitXi(state.data(), i), ref.s[i].xi, tol_unit > 1e-6 ? 0.02 : tol_unit);
        on += ref.on[i];
      }
      ASSERT_EQ(b.OnCount(state.data()), on);
    }
  }
  EXPECT_GT(max_cohorts, 2);
}

TEST(SmaBundle, CohortsWithoutMergeToleranceMatchPerUnitSimulation) {
  RunAgainstReference(60, 0, 0, 1e-9, 1e-9);
}

TEST(SmaBundle, CohortsWithDefaultMergeToleranceStayCloseToPerUnitSimulation) {
  // merge_temperature = 0.5 C, merge_xi = 0.01: the tension stays within 5 mN of the exact
  // per-unit sum (a unit pulls up to 0.45 N), per-unit values within the tolerances.
  RunAgainstReference(60, 0.5, 0.01, 5e-3, 0.5);
}

TEST(SmaBundle, CohortCountGrowsSublinearlyWithBundleSize) {
  // Busy random switching (p_on = p_off = 0.1 every 0.5 s): most units are in a transient, yet
  // 10x the units need well under 10x the cohorts with the default merge tolerances.
  double mean_cohorts[2] = {0, 0};
  const int sizes[2] = {600, 6000};
  for (int k = 0; k < 2; ++k) {
    const SmaBundle b = MakeBundle(sizes[k], 0.5, 0.01);
    std::vector<double> state(b.state_size());
    const double stretch = b.config().unit.prestretch;
    b.Reset(state.data(), 3, stretch);
    int samples = 0;
    for (int step = 0; step < 15000; ++step) {
      if (step % 500 == 0) {
        ASSERT_TRUE(b.Broadcast(state.data(), 0.1, 0.1, stretch).ok());
      }
      b.Advance(state.data(), stretch, 1e-3);
      if (step >= 8000) {
        mean_cohorts[k] += b.NumCohorts(state.data());
        ++samples;
      }
    }
    mean_cohorts[k] /= samples;
  }
  EXPECT_LT(mean_cohorts[1], 5 * mean_cohorts[0])
      << mean_cohorts[0] << " cohorts for 600 units, " << mean_cohorts[1] << " for 6000";
  EXPECT_LT(mean_cohorts[1], 0.2 * 6000);
}

TEST(SmaBundle, UnitsSwitchedTogetherStayOneCohortWhateverTheirNumber) {
  // The Fig. 4 regime: per-step work is one cohort for 6000 units, and the state matches a
  // single unit's.
  const SmaBundle b = MakeBundle(6000, 0.5, 0.01);
  std::vector<double> state(b.state_size());
  const double stretch = b.config().unit.prestretch;
  b.Reset(state.data(), 1, stretch);
  UnitState one = RestState(b.unit(), stretch);
  ASSERT_TRUE(b.Broadcast(state.data(), 1, 0, stretch).ok());
  for (int i = 0; i < 3000; ++i) {
    b.Advance(state.data(), stretch, 1e-3);
    AdvanceUnit(b.unit(), one, true, stretch, 1e-3);
    ASSERT_EQ(b.NumCohorts(state.data()), 1);
  }
  EXPECT_EQ(b.OnCount(state.data()), 6000);
  EXPECT_DOUBLE_EQ(b.UnitTemperature(state.data(), 4321), one.temperature);
  EXPECT_NEAR(b.Tension(state.data(), stretch), 6000 * b.unit().Tension(one.xi, stretch), 1e-9);
}

TEST(SmaBundle, SettledCohortsMergeBackToOne) {
  const SmaBundle b = MakeBundle(600, 0.5, 0.01);
  std::vector<double> state(b.state_size());
  const double stretch = b.config().unit.prestretch;
  b.Reset(state.data(), 5, stretch);
  for (int k = 0; k < 5; ++k) {
    ASSERT_TRUE(b.Broadcast(state.data(), 0.5, 0, stretch).ok());
    for (int i = 0; i < 300; ++i) b.Advance(state.data(), stretch, 1e-3);
  }
  EXPECT_GT(b.NumCohorts(state.data()), 3);
  ASSERT_TRUE(
      b.Broadcast(state.data(), 0, 1, stretch).ok());  // all off: every unit cools to ambient
  for (int i = 0; i < 30000; ++i) b.Advance(state.data(), stretch, 1e-3);
  EXPECT_EQ(b.NumCohorts(state.data()), 1);
  EXPECT_EQ(b.OnCount(state.data()), 0);
  EXPECT_NEAR(b.MeanTemperature(state.data()), 20, 1e-3);
}

TEST(SmaBundle, BroadcastCountsFollowBinomialLaw) {
  // 6000 off units, p_on = 0.3: count ~ Binomial(6000, 0.3), sd 35.5; band +-5 sd.
  const SmaBundle b = MakeBundle(6000, 0.5, 0.01);
  std::vector<double> state(b.state_size());
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    b.Reset(state.data(), seed, 0);
    ASSERT_TRUE(b.Broadcast(state.data(), 0.3, 0.9, 0.0).ok());
    const int on = b.OnCount(state.data());
    EXPECT_NEAR(on, 1800, 5 * 35.5) << "seed " << seed;
    // Then p_off = 0.5 of the on units, p_on = 0 of the off ones: Binomial(on, 0.5).
    ASSERT_TRUE(b.Broadcast(state.data(), 0, 0.5, 0.0).ok());
    EXPECT_NEAR(b.OnCount(state.data()), 0.5 * on, 5 * std::sqrt(on * 0.25));
  }
}

TEST(SmaBundle, SameSeedSameDrawsDifferentSeedDifferentDraws) {
  const SmaBundle b = MakeBundle(600, 0.5, 0.01);
  std::vector<double> s1(b.state_size()), s2(b.state_size()), s3(b.state_size());
  b.Reset(s1.data(), 11, 0);
  b.Reset(s2.data(), 11, 0);
  b.Reset(s3.data(), 12, 0);
  for (auto* s : {&s1, &s2, &s3}) ASSERT_TRUE(b.Broadcast(s->data(), 0.5, 0.5, 0.0).ok());
  EXPECT_EQ(s1, s2);
  EXPECT_NE(s1, s3);
}

TEST(SmaBundle, ZeroCurrentAndSingleUnitAreWellDefined) {
  auto c = BundleConfig::FromText("b", "units=1 current=0");
  ASSERT_TRUE(c.ok()) << c.error();
  auto b = SmaBundle::Create(*c, 1e-3);
  ASSERT_TRUE(b.ok()) << b.error();
  std::vector<double> s(b->state_size());
  b->Reset(s.data(), 1, 3e-3);
  ASSERT_TRUE(b->Broadcast(s.data(), 1, 0, 3e-3).ok());
  for (int i = 0; i < 100; ++i) b->Advance(s.data(), 3e-3, 1e-3);
  EXPECT_EQ(b->OnCount(s.data()), 1);
  EXPECT_EQ(b->Heat(s.data()), 0.0);
  EXPECT_EQ(b->MeanTemperature(s.data()), 20.0);
  EXPECT_EQ(b->Tension(s.data(), 3e-3), 0.0);
  EXPECT_EQ(b->SettledOnTension(3e-3), 0.0);
}

TEST(SmaBundle, RejectsProbabilitiesOutsideUnitInterval) {
  const SmaBundle b = MakeBundle(10, 0.5, 0.01);
  std::vector<double> s(b.state_size());
  b.Reset(s.data(), 1, 0);
  EXPECT_FALSE(b.Broadcast(s.data(), -0.1, 0, 0.0).ok());
  EXPECT_FALSE(b.Broadcast(s.data(), 0, 1.5, 0.0).ok());
  EXPECT_FALSE(b.Broadcast(s.data(), std::nan(""), 0, 0.0).ok());
  EXPECT_EQ(b.OnCount(s.data()), 0);
}

}  // namespace
}  // namespace recruit::sma
