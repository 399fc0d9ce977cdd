// The broadcast census in the bundle (plugin/README.md "Census"): the pulse's heating against
// the closed form of the unit's thermal ODE, the shunt readings against the conducting counts
// and the stated noise, the count over seeds against the binomial of the per-cycle hazard, and
// no change at all without a census.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "common/rng.h"
#include "plugin/bundle.h"

namespace recruit::sma {
namespace file_census_test {

using ::testing::HasSubstr;

SmaBundle Make(const std::string& text, double dt = 1e-3) {
  auto c = BundleConfig::FromText("b", text);
  EXPECT_TRUE(c.ok()) << c.error();
  auto b = SmaBundle::Create(*c, dt);
  EXPECT_TRUE(b.ok()) << b.error();
  return b.value();
}

// Runs a census to its end (whole steps of dt), returns its readings.
SmaBundle::CensusReading RunCensus(const SmaBundle& b, double* s, double x, double dt) {
  EXPECT_TRUE(b.StartCensus(s, x).ok());
  while (b.CensusRunning(s)) b.Advance(s, x, dt);
  return b.LastCensus(s);
}

TEST(CensusConfig, KeysParseAndTheBlockExistsOnlyWithThem) {
  auto c = BundleConfig::FromText("b", "census_on=0.003 census_off=0.001 census_noise=0.02");
  ASSERT_TRUE(c.ok()) << c.error();
  EXPECT_TRUE(c->census.given);
  EXPECT_EQ(c->census.on, 0.003);
  EXPECT_EQ(c->census.off, 0.001);
  EXPECT_EQ(c->census.noise, 0.02);
  const SmaBundle plain = Make("units=30");
  EXPECT_FALSE(plain.has_census());
  EXPECT_EQ(plain.state_size(), SmaBundle::StateSize(30));
  EXPECT_EQ(Make("units=30 census_noise=0").state_size(), SmaBundle::StateSize(30) + 16);
  std::vector<double> s(plain.state_size());
  plain.Reset(s.data(), 1, 4e-3);
  const Status st = plain.StartCensus(s.data(), 4e-3);
  ASSERT_FALSE(st.ok());
  EXPECT_THAT(st.error(), HasSubstr("actuator 'b': no census: give a census key"));
  for (const char* bad : {"census_on=0", "census_off=0.2", "census_noise=-1"}) {
    auto r = BundleConfig::FromText("b", bad);
    ASSERT_FALSE(r.ok()) << bad;
    EXPECT_THAT(r.error(), HasSubstr(std::string(bad) + " is out of range")) << r.error();
  }
}

TEST(Census, WithoutACensusTheBlockChangesNothing) {
  const SmaBundle plain = Make("units=30 open_rate=200");
  const SmaBundle with = Make("units=30 open_rate=200 census_noise=0.01");
  const double x = plain.config().unit.prestretch;
  std::vector<double> a(plain.state_size()), b(with.state_size());
  plain.Reset(a.data(), 5, x);
  with.Reset(b.data(), 5, x);
  Rng control(3);
  for (int step = 0; step < 3000; ++step) {
    if (step % 100 == 0) {
      const double p = control.Uniform(), q = control.Uniform();
      ASSERT_TRUE(plain.Broadcast(a.data(), p, q, x).ok());
      ASSERT_TRUE(with.Broadcast(b.data(), p, q, x).ok());
    }
    plain.Advance(a.data(), x, 1e-3);
    with.Advance(b.data(), x, 1e-3);
    ASSERT_EQ(plain.Tension(a.data(), x), with.Tension(b.data(), x)) << step;
  }
  EXPECT_EQ(plain.Failures(a.data()).open, with.Failures(b.data()).open);
  // The bundle blocks agree up to the census block.
  for (int i = 0; i < plain.state_size(); ++i) ASSERT_EQ(a[i], b[i]) << i;
}

// The unit's lumped thermal ODE, C dT/dt = P - G (T - T_a) with constant P over a phase, has
// T(t) = T_ss + (T0 - T_ss) exp(-t / tau), T_ss = T_a + P / G, tau = C / G.
double ClosedForm(double t0, double t_ss, double t, double tau) {
  return t_ss + (t0 - t_ss) * std::exp(-t / tau);
}

TEST(Census, PulseHeatsOffUnitsAndCoolsOnUnitsByTheClosedFormOfTheThermalOde) {
  const double dt = 1e-3, t_on = 2e-3, t_off = 3e-3;
  const SmaBundle b = Make(
      "units=4 census_on=0.002 census_off=0.003 census_noise=0 "
      "merge_temperature=0 merge_xi=0",
      dt);
  const UnitModel& u = b.unit();
  const double x = b.config().unit.prestretch, ta = b.config().unit.ambient;
  const double tau = u.heat_capacity() / u.conductance();
  std::vector<double> s(b.state_size());
  b.Reset(s.data(), 1, x);
  // Units 0, 1 settled on (austenite), units 2, 3 cold and off.
  ASSERT_TRUE(b.Broadcast(s.data(), 1, 0, x).ok());
  for (int i = 0; i < 20000; ++i) b.Advance(s.data(), x, dt);
  ASSERT_TRUE(b.Broadcast(s.data(), 0, 1, x).ok());  // all off: cools back to ambient
  for (int i = 0; i < 60000; ++i) b.Advance(s.data(), x, dt);
  int hot = -1, cold = -1;
  for (int tries = 0; tries < 50 && (hot < 0 || cold < 0); ++tries) {  // some on, some off
    ASSERT_TRUE(b.Broadcast(s.data(), 0.5, 0.5, x).ok());
    hot = cold = -1;
    for (int i = 0; i < 4; ++i) (b.UnitOn(s.data(), i) ? hot : cold) = i;
  }
  for (int i = 0; i < 20000; ++i) b.Advance(s.data(), x, dt);
  ASSERT_GE(hot, 0);
  ASSERT_GE(cold, 0);
  const double hot0 = b.UnitTemperature(s.data(), hot), cold0 = b.UnitTemperature(s.data(), cold);
  ASSERT_NEAR(cold0, ta, 1e-6);
  ASSERT_EQ(b.UnitXi(s.data(), hot), 0);  // settled austenite: no latent heat in the pulse
  const double f0 = b.Tension(s.data(), x);
  ASSERT_TRUE(b.StartCensus(s.data(), x).ok());
  b.Advance(s.data(), x, dt);
  b.Advance(s.data(), x, dt);  // the end of the on phase
  const double p_cold = u.HeatingPower(true, b.UnitXi(s.data(), cold));
  const double cold1 = ClosedForm(cold0, ta + p_cold / u.conductance(), t_on, tau);
  EXPECT_NEAR(b.UnitTemperature(s.data(), cold), cold1, 1e-9 * (cold1 - ta));
  EXPECT_EQ(b.UnitXi(s.data(), cold), 1);  // far below As: no force from the pulse
  const double hot1 = b.UnitTemperature(s.data(), hot);
  for (int i = 0; i < 3; ++i) b.Advance(s.data(), x, dt);
  EXPECT_FALSE(b.CensusRunning(s.data()));
  EXPECT_NEAR(b.UnitTemperature(s.data(), cold), ClosedForm(cold1, ta, t_off, tau), 1e-12);
  EXPECT_NEAR(b.UnitTemperature(s.data(), hot), ClosedForm(hot1, ta, t_off, tau), 1e-9);
  EXPECT_EQ(b.UnitXi(s.data(), hot), 0);  // 0.1 K of cooling stays above Ms
  EXPECT_EQ(b.Tension(s.data(), x), f0);
  // The rise: P t_on / C to first order in t_on / tau (0.16 K for the default unit).
  EXPECT_NEAR(cold1 - ta, p_cold * t_on / u.heat_capacity(), t_on / tau * (cold1 - ta));
  std::printf("pulse: off unit +%.4f K, on unit %.4f K\n", cold1 - ta,
              b.UnitTemperature(s.data(), hot) - hot0);
  const auto r = b.LastCensus(s.data());
  EXPECT_EQ(r.number, 1);
  EXPECT_EQ(r.on_current, 4 * b.UnitCurrent());
  EXPECT_EQ(r.off_current, 0);
}

TEST(Census, ReadingsCountTheConductingUnitsWithTheStatedNoise) {
  const double dt = 1e-3, sigma = 0.02;
  const SmaBundle b = Make("units=60 failures=0:6:open,0:3:stuck census_noise=0.02 parallel=2", dt);
  EXPECT_EQ(b.UnitCurrent(), 0.36);  // 0.18 A through each of 2 wires
  const double x = b.config().unit.prestretch;
  std::vector<double> s(b.state_size());
  b.Reset(s.data(), 9, x);
  b.Advance(s.data(), x, dt);  // the schedule fires
  ASSERT_EQ(b.Failures(s.data()).open, 6);
  ASSERT_EQ(b.Failures(s.data()).stuck, 3);
  const int n = 2000;
  double sum[2] = {0, 0}, sq[2] = {0, 0};
  for (int k = 0; k < n; ++k) {
    if (k % 40 == 0) {
      ASSERT_TRUE(b.Broadcast(s.data(), 0.3, 0.3, x).ok());
    }
    const auto r = RunCensus(b, s.data(), x, dt);
    ASSERT_EQ(r.number, k + 1);
    const double e[2] = {r.on_current - 54 * b.UnitCurrent(), r.off_current - 3 * b.UnitCurrent()};
    for (int i = 0; i < 2; ++i) sum[i] += e[i], sq[i] += e[i] * e[i];
    ASSERT_EQ(std::lround(r.on_current / b.UnitCurrent()), 54);
    ASSERT_EQ(std::lround(r.off_current / b.UnitCurrent()), 3);
  }
  for (int i = 0; i < 2; ++i) {
    // Mean within 4 standard errors of 0, variance within 4 standard errors (sqrt(2 / n)).
    EXPECT_NEAR(sum[i] / n, 0, 4 * sigma / std::sqrt(n));
    EXPECT_NEAR(sq[i] / n / (sigma * sigma), 1, 4 * std::sqrt(2.0 / n));
  }
}

TEST(Census, CountOverSeedsFollowsTheBinomialOfThePerCycleHazard) {
  // Every unit switched on once with open_per_cycle 0.2: the open count is Binomial(60, 0.2),
  // the census's conducting count 60 minus it.
  const double dt = 1e-3, p = 0.2;
  const SmaBundle b = Make("units=60 open_per_cycle=0.2 census_noise=0.02", dt);
  const double x = b.config().unit.prestretch;
  std::vector<double> s(b.state_size());
  const int seeds = 400;
  double sum = 0, sq = 0;
  for (int seed = 0; seed < seeds; ++seed) {
    b.Reset(s.data(), 1000 + seed, x);
    ASSERT_TRUE(b.Broadcast(s.data(), 1, 0, x).ok());
    const auto r = RunCensus(b, s.data(), x, dt);
    const long open = 60 - std::lround(r.on_current / b.UnitCurrent());
    ASSERT_EQ(open, b.Failures(s.data()).open);
    sum += open;
    sq += open * open;
  }
  const double mean = sum / seeds, var = sq / seeds - mean * mean;
  const double mu = 60 * p, v = 60 * p * (1 - p);
  EXPECT_NEAR(mean, mu, 4 * std::sqrt(v / seeds));
  // Var of the sample variance ~ 2 v^2 / n (near-normal counts): 4 standard errors.
  EXPECT_NEAR(var, v, 4 * v * std::sqrt(2.0 / seeds));
}

TEST(Census, ABlockCopiedMidPulseContinuesExactly) {
  const double dt = 1e-3;
  const SmaBundle b = Make("units=20 census_on=0.003 census_noise=0.05 stuck_rate=100", dt);
  const double x = b.config().unit.prestretch;
  std::vector<double> s(b.state_size());
  b.Reset(s.data(), 4, x);
  ASSERT_TRUE(b.Broadcast(s.data(), 0.5, 0, x).ok());
  for (int i = 0; i < 500; ++i) b.Advance(s.data(), x, dt);
  ASSERT_TRUE(b.StartCensus(s.data(), x).ok());
  EXPECT_FALSE(b.StartCensus(s.data(), x).ok());  // one census at a time
  b.Advance(s.data(), x, dt);
  std::vector<double> copy = s;
  for (int i = 0; i < 10; ++i) {
    b.Advance(s.data(), x, dt);
    b.Advance(copy.data(), x, dt);
  }
  EXPECT_EQ(s, copy);
  EXPECT_EQ(b.LastCensus(s.data()).number, 1);
}

}  // namespace file_census_test
}  // namespace recruit::sma
