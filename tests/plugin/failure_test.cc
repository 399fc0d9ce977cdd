// Unit failures and fatigue in the bundle (plugin/README.md "Failures"): hazard rates against
// Monte Carlo binomial bands, the schedule's exact counts, failed units' physics against a plain
// per-unit simulation, the fatigue law against its closed form, and exact copy and reset.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "common/rng.h"
#include "plugin/bundle.h"

namespace recruit::sma {
namespace file_failure_test {

using ::testing::HasSubstr;

SmaBundle Make(const std::string& text, double dt = 1e-2) {
  auto c = BundleConfig::FromText("b", text);
  EXPECT_TRUE(c.ok()) << c.error();
  auto b = SmaBundle::Create(*c, dt);
  EXPECT_TRUE(b.ok()) << b.error();
  return b.value();
}

// 4 sigma of a binomial count, plus 1.
double Band(double n, double p) { return 4 * std::sqrt(n * p * (1 - p)) + 1; }

TEST(FailureConfig, KeysParseAndImpossibleValuesAreRefused) {
  auto c =
      BundleConfig::FromText("b", "open_rate=2 stuck_per_cycle=0.01 failures=3:2:stuck,1:4:open");
  ASSERT_TRUE(c.ok()) << c.error();
  EXPECT_TRUE(c->failure.given);
  EXPECT_EQ(c->failure.open_rate, 2);
  ASSERT_EQ(c->failure.schedule.size(), 2u);
  EXPECT_EQ(c->failure.schedule[0].time, 1);  // sorted by time
  EXPECT_EQ(c->failure.schedule[0].count, 4);
  EXPECT_FALSE(c->failure.schedule[0].stuck);
  EXPECT_TRUE(c->failure.schedule[1].stuck);
  EXPECT_FALSE(BundleConfig::FromText("b", "units=10")->failure.given);
  struct Bad {
    const char* text;
    const char* message;
  };
  for (const Bad& bad : {
           Bad{"open_rate=-1",
               "open_rate=-1 is out of range: must be in [0, 3600] per hour heated"},
           Bad{"stuck_per_cycle=1.5", "stuck_per_cycle=1.5 is out of range: must be in [0, 1]"},
           Bad{"open_per_cycle=0.6 stuck_per_cycle=0.5", "add to 1.1, more than 1"},
           Bad{"fatigue_loss=1", "fatigue_loss=1 is out of range: must be in [0, 0.9]"},
           Bad{"fatigue_cycles=0", "fatigue_cycles=0 is out of range"},
           Bad{"failures=3:2:melted", "failures=3:2:melted is invalid"},
           Bad{"failures=-1:2:open", "failures=-1:2:open is invalid"},
           Bad{"failures=1:2.5:open", "is invalid"},
           Bad{"units=10 failures=1:6:open,2:5:stuck",
               "the schedule fails 11 units of a bundle of 10"},
       }) {
    auto r = BundleConfig::FromText("b", bad.text);
    ASSERT_FALSE(r.ok()) << bad.text;
    EXPECT_THAT(r.error(), HasSubstr(bad.message)) << r.error();
    EXPECT_THAT(r.error(), HasSubstr("actuator 'b'"));
  }
}

TEST(Failures, NoFailureKeyKeepsTheLayoutAndAZeroHazardChangesNothing) {
  const SmaBundle plain = Make("units=30");
  const SmaBundle zero = Make("units=30 open_rate=0 stuck_per_cycle=0");
  EXPECT_FALSE(plain.has_failures());
  EXPECT_EQ(plain.state_size(), SmaBundle::StateSize(30));
  EXPECT_EQ(zero.state_size(), SmaBundle::StateSize(30) + SmaBundle::FailureBlockSize(30));
  const double x = plain.config().unit.prestretch;
  std::vector<double> a(plain.state_size()), b(zero.state_size());
  plain.Reset(a.data(), 5, x);
  zero.Reset(b.data(), 5, x);
  Rng control(3);
  for (int step = 0; step < 2000; ++step) {
    if (step % 50 == 0) {
      const double p = control.Uniform();
      ASSERT_TRUE(plain.Broadcast(a.data(), p, 1 - p, x).ok());
      ASSERT_TRUE(zero.Broadcast(b.data(), p, 1 - p, x).ok());
    }
    plain.Advance(a.data(), x, 1e-2);
    zero.Advance(b.data(), x, 1e-2);
  }
  // The common part of the blocks is bit-identical.
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0);
  EXPECT_EQ(zero.Failures(b.data()).working, 30);
}

// Hazard per hour heated: units held on for T fail with p = 1 - exp(-rate T); off units never.
TEST(Failures, HeatedHazardGivesBinomialCountsSplitByRate) {
  const int units = 40, seeds = 200;
  const double open_rate = 240, stuck_rate = 120, T = 3;  // per hour heated; s
  const SmaBundle b = Make("units=40 open_rate=240 stuck_rate=120");
  const double x = b.config().unit.prestretch;
  long failed = 0, open = 0, off_failed = 0;
  for (int seed = 0; seed < seeds; ++seed) {
    std::vector<double> s(b.state_size()), cold(b.state_size());
    b.Reset(s.data(), 100 + seed, x);
    b.Reset(cold.data(), 100 + seed, x);
    ASSERT_TRUE(b.Broadcast(s.data(), 1, 0, x).ok());
    for (int step = 0; step < 300; ++step) {
      b.Advance(s.data(), x, 1e-2);
      b.Advance(cold.data(), x, 1e-2);
    }
    const auto f = b.Failures(s.data());
    EXPECT_EQ(f.working + f.open + f.stuck, units);
    failed += f.open + f.stuck;
    open += f.open;
    off_failed += units - b.Failures(cold.data()).working;
  }
  const double n = double(units) * seeds;
  const double p = -std::expm1(-(open_rate + stuck_rate) / 3600 * T);
  EXPECT_NEAR(failed, n * p, Band(n, p));
  EXPECT_NEAR(open, failed * 2.0 / 3, Band(failed, 2.0 / 3));
  EXPECT_EQ(off_failed, 0);
}

// The same law where n p is large (one Bernoulli draw per unit instead of the inversion).
TEST(Failures, HeatedHazardIsRightForLargeCohortsAndRates) {
  const int units = 200, seeds = 30;
  const SmaBundle b = Make("units=200 open_rate=3600", 0.1);  // 1 per second heated
  const double x = b.config().unit.prestretch;
  long failed = 0;
  for (int seed = 0; seed < seeds; ++seed) {
    std::vector<double> s(b.state_size());
    b.Reset(s.data(), 300 + seed, x);
    ASSERT_TRUE(b.Broadcast(s.data(), 1, 0, x).ok());
    for (int step = 0; step < 10; ++step) b.Advance(s.data(), x, 0.1);
    failed += b.Failures(s.data()).open;
  }
  const double n = double(units) * seeds, p = -std::expm1(-1.0);
  EXPECT_NEAR(failed, n * p, Band(n, p));
}

// Hazard per cycle: after K on/off cycles a unit has failed with p = 1 - (1 - q)^K.
TEST(Failures, CycleHazardGivesBinomialCounts) {
  const int units = 50, seeds = 40, K = 10;
  const double q = 0.02;
  const SmaBundle b = Make("units=50 open_per_cycle=0.015 stuck_per_cycle=0.005");
  const double x = b.config().unit.prestretch;
  long failed = 0, stuck = 0;
  for (int seed = 0; seed < seeds; ++seed) {
    std::vector<double> s(b.state_size());
    b.Reset(s.data(), 7 + seed, x);
    for (int k = 0; k < K; ++k) {
      ASSERT_TRUE(b.Broadcast(s.data(), 1, 0, x).ok());
      b.Advance(s.data(), x, 1e-2);
      ASSERT_TRUE(b.Broadcast(s.data(), 0, 1, x).ok());
      b.Advance(s.data(), x, 1e-2);
    }
    const auto f = b.Failures(s.data());
    failed += f.open + f.stuck;
    stuck += f.stuck;
  }
  const double n = double(units) * seeds, p = 1 - std::pow(1 - q, K);
  EXPECT_NEAR(failed, n * p, Band(n, p));
  EXPECT_NEAR(stuck, failed * 0.25, Band(failed, 0.25));
}

// The schedule fails exactly its counts at its times; failed units then follow their own
// physics: the same run against one UnitState per unit, open ones never heated, stuck ones
// always, working ones switched by the same draws (failed units draw too).
TEST(Failures, ScheduledFailuresMatchAPerUnitSimulation) {
  const int units = 24;
  auto c = BundleConfig::FromText("b", "units=24 failures=1:5:open,2:3:stuck");
  ASSERT_TRUE(c.ok()) << c.error();
  c->merge_temperature = 0;
  c->merge_xi = 0;
  const double dt = 1e-2;
  const SmaBundle b = SmaBundle::Create(*c, dt).value();
  const double x = b.config().unit.prestretch;
  std::vector<double> s(b.state_size());
  b.Reset(s.data(), 9, x);
  std::vector<UnitState> ref(units, RestState(b.unit(), x));
  std::vector<bool> on(units, false);
  Rng draws(9), control(4);
  for (int step = 1; step <= 400; ++step) {
    if (step % 20 == 1) {
      const double p_on = control.Uniform(), p_off = control.Uniform();
      ASSERT_TRUE(b.Broadcast(s.data(), p_on, p_off, x).ok());
      for (int i = 0; i < units; ++i) {
        const double u = draws.Uniform();
        if (b.UnitFailure(s.data(), i) == 0 && u < (on[i] ? p_off : p_on)) on[i] = !on[i];
      }
    }
    b.Advance(s.data(), x, dt);
    for (int i = 0; i < units; ++i) AdvanceUnit(b.unit(), ref[i], on[i], x, dt);
    // Failures happen at the end of the step that reaches their time.
    for (int i = 0; i < units; ++i) {
      const int mode = b.UnitFailure(s.data(), i);
      if (mode != 0) on[i] = mode == 2;
    }
    const auto f = b.Failures(s.data());
    const double t = step * dt;
    EXPECT_EQ(f.open, t >= 1 - 1e-9 ? 5 : 0) << t;
    EXPECT_EQ(f.stuck, t >= 2 - 1e-9 ? 3 : 0) << t;
    for (int i = 0; i < units; ++i) {
      ASSERT_EQ(b.UnitOn(s.data(), i), on[i]) << "unit " << i << " t " << t;
      ASSERT_NEAR(b.UnitTemperature(s.data(), i), ref[i].temperature, 1e-9) << i;
      ASSERT_NEAR(b.UnitXi(s.data(), i), ref[i].xi, 1e-9) << i;
    }
  }
  // Open units never heat again: after a long all-on broadcast they sit at ambient.
  ASSERT_TRUE(b.Broadcast(s.data(), 1, 0, x).ok());
  for (int step = 0; step < 1000; ++step) b.Advance(s.data(), x, dt);
  for (int i = 0; i < units; ++i) {
    const int mode = b.UnitFailure(s.data(), i);
    if (mode == 1) {
      EXPECT_NEAR(b.UnitTemperature(s.data(), i), b.config().unit.ambient, 1e-3);
    }
    if (mode != 1) {
      EXPECT_TRUE(b.UnitOn(s.data(), i));
    }
  }
  // Stuck units stay on through an all-off broadcast.
  ASSERT_TRUE(b.Broadcast(s.data(), 0, 1, x).ok());
  EXPECT_EQ(b.OnCount(s.data()), 3);
}

// Fatigue: with exponent 0 every full cycle adds damage 1 (xi reaches 0), so after K cycles
// the force scale is the closed form 1 - a (1 - exp(-K / N_p)) and the settled on tension
// scales by it.
TEST(Fatigue, FullCyclesFollowTheExponentialShakedownLaw) {
  const double a = 0.2, Np = 5;
  const SmaBundle b = Make("units=3 fatigue_loss=0.2 fatigue_cycles=5 fatigue_exponent=0", 0.05);
  const double x = b.config().unit.prestretch;
  std::vector<double> s(b.state_size());
  b.Reset(s.data(), 1, x);
  double fresh_on = 0;
  for (int k = 1; k <= 12; ++k) {
    ASSERT_TRUE(b.Broadcast(s.data(), 1, 0, x).ok());
    for (int step = 0; step < 200; ++step) b.Advance(s.data(), x, 0.05);  // 10 s: settled
    if (k == 1) fresh_on = b.Tension(s.data(), x);
    const double before = b.UnitForceScale(s.data(), 0);
    EXPECT_NEAR(before, 1 - a * (1 - std::exp(-(k - 1) / Np)), 1e-12) << k;
    EXPECT_NEAR(b.Tension(s.data(), x), before * fresh_on, 1e-9 * fresh_on) << k;
    ASSERT_TRUE(b.Broadcast(s.data(), 0, 1, x).ok());
    for (int step = 0; step < 200; ++step) b.Advance(s.data(), x, 0.05);
  }
  EXPECT_NEAR(b.UnitForceScale(s.data(), 2), 1 - a * (1 - std::exp(-12 / Np)), 1e-12);
}

// Faster with stress: damage per cycle scales as (stress / reference)^m.
TEST(Fatigue, DamagePerCycleScalesWithStressToTheExponent) {
  const double m = 1.5;
  double damage[2], stress[2];
  const double prestrain[2] = {0.01, 0.02};
  for (int c = 0; c < 2; ++c) {
    const SmaBundle b = Make(
        "units=1 fatigue_loss=0.5 fatigue_cycles=1e6 fatigue_exponent=1.5 "
        "prestrain=" +
            std::to_string(prestrain[c]),
        0.05);
    const double x = b.config().unit.prestretch;
    std::vector<double> s(b.state_size());
    b.Reset(s.data(), 1, x);
    ASSERT_TRUE(b.Broadcast(s.data(), 1, 0, x).ok());
    for (int step = 0; step < 200; ++step) b.Advance(s.data(), x, 0.05);
    stress[c] = b.unit().WireStress(b.Tension(s.data(), x));
    const double xi = b.UnitXi(s.data(), 0);
    ASSERT_TRUE(b.Broadcast(s.data(), 0, 1, x).ok());
    // Invert the law for the damage of this one cycle.
    damage[c] = -1e6 * std::log1p(-(1 - b.UnitForceScale(s.data(), 0)) / 0.5);
    EXPECT_NEAR(damage[c], (1 - xi) * std::pow(stress[c] / 172e6, m), 1e-6 * damage[c]);
  }
  EXPECT_GT(stress[1], stress[0]);
  EXPECT_NEAR(damage[1] / damage[0], std::pow(stress[1] / stress[0], m), 1e-4);
}

// Copy and reset stay exact with failures and fatigue: a copied block continues bit for bit,
// and Reset gives back the fresh block.
TEST(Failures, BlockCopyContinuesExactlyAndResetRestores) {
  const SmaBundle b = Make(
      "units=30 open_rate=600 stuck_rate=300 open_per_cycle=0.02 fatigue_loss=0.1 "
      "failures=1:3:open");
  const double x = b.config().unit.prestretch;
  std::vector<double> s(b.state_size()), fresh(b.state_size());
  b.Reset(fresh.data(), 11, x);
  s = fresh;
  Rng control(2);
  auto run = [&](std::vector<double>& st, Rng ctl, int steps) {
    for (int i = 0; i < steps; ++i) {
      if (i % 25 == 0) {
        const double p = ctl.Uniform();
        EXPECT_TRUE(b.Broadcast(st.data(), p, 1 - p, x).ok());
      }
      b.Advance(st.data(), x, 1e-2);
    }
  };
  run(s, control, 300);
  std::vector<double> copy = s;
  run(s, Rng(8), 500);
  run(copy, Rng(8), 500);
  EXPECT_EQ(std::memcmp(s.data(), copy.data(), s.size() * sizeof(double)), 0);
  EXPECT_GT(b.Failures(s.data()).open, 3);  // the hazards acted too
  for (double v : s) EXPECT_TRUE(std::isfinite(v));
  b.Reset(s.data(), 11, x);
  EXPECT_EQ(std::memcmp(s.data(), fresh.data(), s.size() * sizeof(double)), 0);
}

}  // namespace file_failure_test
}  // namespace recruit::sma
