// The bundle's cohort bookkeeping against a plain per-unit simulation (one UnitState per unit,
// the same random draws), and the broadcast statistics against the binomial law.
#include "plugin/bundle.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "common/rng.h"

namespace recruit::sma {
namespace file_bundle_test {

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

// A block that keeps its telemetry at each Advance (ObserveEachStep) steps exactly as one that
// does not, and ReadTelemetry gives from it, bit for bit, what the other block's separate pass
// over the cohorts gives: at the observed extension (kept) and at another (summed afresh), with
// broadcasts, merges and few and many cohorts along the way.
TEST(SmaBundleTelemetry, KeptTelemetryIsTheSeparatePassBitForBit) {
  for (const char* text : {"units=60", "units=60 merge_temperature=0 merge_xi=0",
                           "units=12 unit_model=binned bins=3", "units=40 update_period=0.004"}) {
    auto c = BundleConfig::FromText("b", text);
    ASSERT_TRUE(c.ok()) << c.error();
    auto b = SmaBundle::Create(*c, 2e-3);
    ASSERT_TRUE(b.ok()) << b.error();
    const double e0 = b->config().unit.prestretch;
    std::vector<double> kept(b->state_size()), plain(b->state_size());
    b->Reset(kept.data(), 5, e0);
    b->Reset(plain.data(), 5, e0);
    SmaBundle::ObserveEachStep(kept.data(), true);
    Rng rng(3);
    auto same = [](const SmaBundle::Telemetry& x, const SmaBundle::Telemetry& y) {
      auto eq = [](double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; };
      return x.on_count == y.on_count && eq(x.tension, y.tension) &&
             eq(x.mean_temperature, y.mean_temperature) && eq(x.mean_xi, y.mean_xi) &&
             eq(x.max_temperature, y.max_temperature) && eq(x.max_wire_stress, y.max_wire_stress);
    };
    int most = 0;
    for (int step = 0; step < 3000; ++step) {
      const double stretch = e0 * (1 + 0.05 * std::sin(step * 1e-3));
      if (step % 100 == 0) {
        const double p_on = 0.4 * rng.Uniform(), p_off = 0.3 * rng.Uniform();
        ASSERT_TRUE(b->Broadcast(kept.data(), p_on, p_off, stretch).ok());
        ASSERT_TRUE(b->Broadcast(plain.data(), p_on, p_off, stretch).ok());
      }
      const double seen = stretch + 1e-6 * (rng.Uniform() - 0.5);
      b->Advance(kept.data(), stretch, 2e-3, seen);
      b->Advance(plain.data(), stretch, 2e-3, seen);
      // The blocks differ only in the telemetry slots of the header (15 .. 23).
      for (size_t i = 0; i < kept.size(); ++i) {
        if (i >= 15 && i < 24) continue;
        ASSERT_TRUE(std::memcmp(&kept[i], &plain[i], sizeof(double)) == 0)
            << text << " step " << step << " slot " << i;
      }
      for (double at : {seen, stretch}) {
        ASSERT_TRUE(same(b->ReadTelemetry(kept.data(), at), b->ReadTelemetry(plain.data(), at)))
            << text << " step " << step << " at " << at;
      }
      most = std::max(most, b->NumCohorts(kept.data()));
    }
    EXPECT_GT(most, 1) << text;
  }
}

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
      // Peaks: the hottest unit and the most stressed wire of the per-unit simulation.
      double t_max = -1e9, f_max = 0;
      for (const auto& u : ref.s) {
        t_max = std::max(t_max, u.temperature);
        f_max = std::max(f_max, b.unit().Tension(u.xi, stretch));
      }
      ASSERT_NEAR(b.MaxTemperature(state.data()), t_max, tol_unit);
      const double area = 3.14159265358979323846 * 0.25e-8;  // 0.1 mm wire, plain wire law
      ASSERT_NEAR(b.MaxWireStress(state.data(), stretch), f_max / area,
                  tol_force > 1e-6 ? 2e6 : 1e-3);
    }
  }
  EXPECT_GT(max_cohorts, 2);
}

TEST(SmaBundle, CohortsWithoutMergeToleranceMatchPerUnitSimulation) {
  RunAgainstReference(60, 0, 0, 1e-9, 1e-9);
}

TEST(SmaBundle, CohortsWithDefaultMergeToleranceStayCloseToPerUnitSimulation) {
  // merge_temperature = 0.5 C, merge_xi = 0.01: the tension stays within 10 mN of the exact
  // per-unit sum, per-unit values within the tolerances. A default unit's force moves by
  // 0.45 N over the whole of xi, so one merge of units 0.01 apart shifts a unit's share of the
  // force by up to ~5 mN through the curvature of k(xi) (xi - xi_L); repeated merges while
  // units transform add up to about twice that (5.1 mN seen with seed 42).
  RunAgainstReference(60, 0.5, 0.01, 1e-2, 0.5);
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
  EXPECT_EQ(b->MaxTemperature(s.data()), 20.0);
  EXPECT_EQ(b->MaxWireStress(s.data(), 3e-3), 0.0);
  EXPECT_EQ(b->OnCount(s.data()), 1);
  EXPECT_EQ(b->Heat(s.data()), 0.0);
  EXPECT_EQ(b->MeanTemperature(s.data()), 20.0);
  EXPECT_EQ(b->Tension(s.data(), 3e-3), 0.0);
  EXPECT_EQ(b->SettledOnTension(3e-3), 0.0);
}

// The paper's Fig. 4 without MuJoCo: 60 default units at their prestretch (isometric), all
// switched on at t = 1 s, integrated at dt = 1 ms to t = 12 s. Bands: steady force 25-30 N
// (the paper's "about 25-30 N"); 75 % of it 1.5-2.5 s after the switch (paper: "about 2 s");
// settled into +-5 % (last exit) no later than 6 s (paper: "about 5 s"). The model settles
// much earlier than the paper (about 2.3 s): with the wire stress held to 172 MPa and the
// on-temperature to 120 C the force can only build over a ~20 K band that a lumped wire crosses
// in about a quarter of a time constant (docs/sma-units.md); the test keeps only the upper
// bound the paper's figure implies. Peaks stay within the datasheet limits all along.
TEST(SmaBundle, IsometricStepMatchesPaperFigure4WithinDatasheetLimits) {
  auto c = BundleConfig::FromText("fig4", "");
  ASSERT_TRUE(c.ok()) << c.error();
  auto bundle = SmaBundle::Create(*c, 1e-3);
  ASSERT_TRUE(bundle.ok()) << bundle.error();
  const SmaBundle& b = *bundle;
  ASSERT_EQ(b.num_units(), 60);
  const double stretch = b.config().unit.prestretch;
  std::vector<double> state(b.state_size());
  b.Reset(state.data(), 1, stretch);
  std::vector<double> t, f;
  double peak_temp = 0, peak_stress = 0;
  for (int i = 1; i <= 12000; ++i) {
    if (i == 1001) {
      ASSERT_TRUE(b.Broadcast(state.data(), 1, 0, stretch).ok());  // t = 1 s
    }
    b.Advance(state.data(), stretch, 1e-3);
    t.push_back(i * 1e-3);
    f.push_back(b.Tension(state.data(), stretch));
    peak_temp = std::max(peak_temp, b.MaxTemperature(state.data()));
    peak_stress = std::max(peak_stress, b.MaxWireStress(state.data(), stretch));
  }
  const double steady = f.back();
  double t75 = -1, settle = 0;
  for (size_t i = 0; i < t.size(); ++i) {
    if (t[i] <= 1.0) {
      ASSERT_EQ(f[i], 0.0);  // off: slack, no force
      continue;
    }
    if (t75 < 0 && f[i] >= 0.75 * steady) t75 = t[i] - 1.0;
    if (std::abs(f[i] - steady) > 0.05 * steady) settle = t[i] - 1.0;
  }
  std::printf(
      "Fig. 4: steady %.2f N, 75 %% at %.3f s, settled (+-5 %%) at %.3f s, peak %.1f C, "
      "%.1f MPa\n",
      steady, t75, settle, peak_temp, peak_stress / 1e6);
  EXPECT_GE(steady, 25);
  EXPECT_LE(steady, 30);
  EXPECT_GE(t75, 1.5);
  EXPECT_LE(t75, 2.5);
  EXPECT_GT(settle, t75);
  EXPECT_LE(settle, 6.0);
  EXPECT_LE(peak_temp, b.limits().max_temperature);
  EXPECT_LE(peak_stress, b.limits().max_wire_stress);
  EXPECT_LE(b.config().unit.current, b.limits().max_current);
  // The settled force is what SettledOnTension predicts for one unit, times 60.
  EXPECT_NEAR(steady, 60 * b.SettledOnTension(stretch), 1e-6 * steady);
}

TEST(SmaBundle, ParallelWiresDoubleTheBundleForceSeriesSegmentsDoubleItsStroke) {
  auto make = [](const std::string& text) {
    auto c = BundleConfig::FromText("b", "units=10 " + text);
    EXPECT_TRUE(c.ok()) << c.error();
    auto b = SmaBundle::Create(*c, 1e-3);
    EXPECT_TRUE(b.ok()) << b.error();
    return b.value();
  };
  const SmaBundle one = make(""), two = make("parallel=2"), ser = make("series=2");
  const double e = one.config().unit.prestretch;
  std::vector<double> s1(one.state_size()), s2(two.state_size()), s3(ser.state_size());
  one.Reset(s1.data(), 1, e);
  two.Reset(s2.data(), 1, e);
  ser.Reset(s3.data(), 1, 2 * e);
  ASSERT_TRUE(one.Broadcast(s1.data(), 1, 0, e).ok());
  ASSERT_TRUE(two.Broadcast(s2.data(), 1, 0, e).ok());
  ASSERT_TRUE(ser.Broadcast(s3.data(), 1, 0, 2 * e).ok());
  for (int i = 0; i < 4000; ++i) {
    one.Advance(s1.data(), e, 1e-3);
    two.Advance(s2.data(), e, 1e-3);
    ser.Advance(s3.data(), 2 * e, 1e-3);
    if (i % 500 == 499) {
      const double f1 = one.Tension(s1.data(), e);
      // Same per-segment stretch: parallel = 2 doubles the force at the same wire stress
      // (each wire carries half, so the stress shift and the transient are unchanged).
      ASSERT_NEAR(two.Tension(s2.data(), e), 2 * f1, 1e-9 * (1 + f1)) << "step " << i;
      ASSERT_NEAR(two.MaxWireStress(s2.data(), e), one.MaxWireStress(s1.data(), e), 1e-3);
      // series = 2 at twice the extension: every segment sees e, same force.
      ASSERT_NEAR(ser.Tension(s3.data(), 2 * e), f1, 1e-9 * (1 + f1)) << "step " << i;
    }
  }
  EXPECT_GT(one.Tension(s1.data(), e), 0.4 * 10);
}

// Traces recorded (printf %.17g) from the previous implementation, the scalar per-cohort update
// on an array-of-structs cohort block (commit 00dea36), kept as the reference for the batched
// structure-of-arrays update: every cohort's state is bit-identical; the bundle's sums
// (tension, means) add the cohorts in four partial sums instead of one, which moves them by a
// few ulp when there are several cohorts (at most 4.4e-16 relative in these traces). Tolerance
// 1e-12 relative; cohort counts exact.
double Rel(double got, double want) { return std::abs(got - want) / std::max(std::abs(want), 1.0); }

TEST(SmaBundle, Figure4TraceUnchangedFromScalarImplementation) {
  // 60 default units at the prestretch, on at t = 1 s, off at t = 12 s, 1 ms steps.
  struct Row {
    int step;
    double tension, mean_t, mean_xi;
  };
  const Row want[] = {
      {1000, 0, 20, 1},
      {2000, 0.20644201418081279, 68.610248053647226, 0.99206859778370038},
      {3000, 18.847643610278102, 78.229409777791759, 0.29477142790902278},
      {4000, 26.840548396170192, 97.84636517435716, 0},
      {6000, 26.840548396170192, 113.26965342781907, 0},
      {12000, 26.840548396170192, 115.58112563972321, 0},
      {13000, 25.551408553975882, 55.865912169533587, 0.047475354439178809},
      {14000, 5.5391257213130629, 46.173377668890268, 0.78978890933006496},
      {15000, 0, 32.121217831423671, 1},
      {16000, 0, 24.380249943656075, 1},
  };
  const SmaBundle b = MakeBundle(60, 0.5, 0.01);
  const double e = b.config().unit.prestretch;
  std::vector<double> s(b.state_size());
  b.Reset(s.data(), 1, e);
  int k = 0;
  for (int i = 1; i <= 16000; ++i) {
    if (i == 1001) {
      ASSERT_TRUE(b.Broadcast(s.data(), 1, 0, e).ok());
    }
    if (i == 12001) {
      ASSERT_TRUE(b.Broadcast(s.data(), 0, 1, e).ok());
    }
    b.Advance(s.data(), e, 1e-3);
    if (i != want[k].step) continue;
    EXPECT_LE(Rel(b.Tension(s.data(), e), want[k].tension), 1e-12) << "step " << i;
    EXPECT_LE(Rel(b.MeanTemperature(s.data()), want[k].mean_t), 1e-12) << "step " << i;
    EXPECT_LE(Rel(b.MeanXi(s.data()), want[k].mean_xi), 1e-12) << "step " << i;
    EXPECT_EQ(b.NumCohorts(s.data()), 1);
    ++k;
  }
  EXPECT_EQ(k, 10);
}

TEST(SmaBundle, RandomSwitchingTraceUnchangedFromScalarImplementation) {
  // 60 units, seed 1, p_on = p_off = 0.1 every 0.5 s (the benchmark's busy regime), 20 s.
  struct Row {
    int step;
    double tension, mean_t, mean_xi;
    int cohorts;
  };
  const Row want[] = {
      {999, 0.020644201418081279, 26.691626593360905, 0.99920685977837009, 4},
      {2999, 4.982462807568198, 38.962945061564717, 0.81381690095059556, 12},
      {4999, 8.9892536748211214, 53.746933111687831, 0.66457995921965285, 22},
      {6999, 11.331848271379535, 59.247126319662634, 0.57728912491901596, 32},
      {8999, 11.997609012765132, 64.34040035219995, 0.55239368312072779, 27},
      {10999, 14.385504746992048, 69.912192761418908, 0.4637082037860471, 27},
      {12999, 13.122565311704328, 66.738544040706728, 0.51051183088196317, 32},
      {13999, 13.0123238940009, 67.868305730702431, 0.51460118539853095, 33},
      {15999, 12.609948168723635, 59.590959021411869, 0.52943810722851248, 31},
      {17999, 11.21037305469425, 61.727902585893411, 0.58181901168837591, 30},
      {19999, 13.123087095196761, 64.877918135327917, 0.51065814989523628, 30},
  };
  const SmaBundle b = MakeBundle(60, 0.5, 0.01);
  const double e = b.config().unit.prestretch;
  std::vector<double> s(b.state_size());
  b.Reset(s.data(), 1, e);
  int k = 0;
  for (int i = 0; i < 20000; ++i) {
    if (i % 500 == 0) {
      ASSERT_TRUE(b.Broadcast(s.data(), 0.1, 0.1, e).ok());
    }
    b.Advance(s.data(), e, 1e-3);
    if (i != want[k].step) continue;
    EXPECT_LE(Rel(b.Tension(s.data(), e), want[k].tension), 1e-12) << "step " << i;
    EXPECT_LE(Rel(b.MeanTemperature(s.data()), want[k].mean_t), 1e-12) << "step " << i;
    EXPECT_LE(Rel(b.MeanXi(s.data()), want[k].mean_xi), 1e-12) << "step " << i;
    EXPECT_EQ(b.NumCohorts(s.data()), want[k].cohorts) << "step " << i;
    ++k;
  }
  EXPECT_EQ(k, 11);
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// ReadTelemetry and Summarize (one pass) give what the separate reads give, bit for bit, along a
// random-switching run with merges, at a taut and a slack extension.
TEST(SmaBundle, ObserveAndSummarizeEqualTheSeparateReads) {
  const SmaBundle b = MakeBundle(60, 0.5, 0.01);
  const double e = b.config().unit.prestretch;
  std::vector<double> s(b.state_size());
  b.Reset(s.data(), 3, e);
  int checks = 0;
  for (int i = 0; i < 6000; ++i) {
    if (i % 300 == 0) {
      ASSERT_TRUE(b.Broadcast(s.data(), 0.2, 0.1, e).ok());
    }
    b.Advance(s.data(), e, 1e-3);
    if (i % 37 != 0) continue;
    for (double stretch : {e, 0.8 * e, -e}) {
      const double* st = s.data();
      const SmaBundle::Telemetry t = b.ReadTelemetry(st, stretch);
      EXPECT_EQ(t.on_count, b.OnCount(st));
      EXPECT_TRUE(SameBits(t.tension, b.Tension(st, stretch))) << "step " << i;
      EXPECT_TRUE(SameBits(t.mean_temperature, b.MeanTemperature(st))) << "step " << i;
      EXPECT_TRUE(SameBits(t.mean_xi, b.MeanXi(st))) << "step " << i;
      EXPECT_TRUE(SameBits(t.max_temperature, b.MaxTemperature(st))) << "step " << i;
      EXPECT_TRUE(SameBits(t.max_wire_stress, b.MaxWireStress(st, stretch))) << "step " << i;
      // and against the per-unit debug interface: the scalar maxima over units
      double top_f = 0, top_t = b.UnitTemperature(st, 0);
      for (int u = 0; u < b.num_units(); ++u) {
        top_f = std::max(top_f, b.unit().Tension(b.UnitXi(st, u), stretch));
        top_t = std::max(top_t, b.UnitTemperature(st, u));
      }
      EXPECT_TRUE(SameBits(t.max_wire_stress, b.unit().WireStress(top_f))) << "step " << i;
      EXPECT_TRUE(SameBits(t.max_temperature, top_t)) << "step " << i;
      const SmaBundle::Summary sum = b.Summarize(st, stretch);
      EXPECT_EQ(sum.on_count, t.on_count);
      EXPECT_TRUE(SameBits(sum.tension, t.tension));
      EXPECT_TRUE(SameBits(sum.mean_temperature, t.mean_temperature));
      EXPECT_TRUE(SameBits(sum.mean_xi, t.mean_xi));
      ++checks;
    }
  }
  EXPECT_GT(checks, 400);
}

// The tension the sensor keeps (SummarizeAndKeep) is what TakeTension returns at that extension
// and only there, is taken once (the block is then as before), and never outlives a change of
// the units (Broadcast, Advance, Reset).
TEST(SmaBundle, KeptTensionIsTakenOnceAtItsExtensionAndDroppedWhenUnitsChange) {
  const SmaBundle b = MakeBundle(60, 0.5, 0.01);
  const double e = b.config().unit.prestretch;
  std::vector<double> s(b.state_size());
  b.Reset(s.data(), 9, e);
  ASSERT_TRUE(b.Broadcast(s.data(), 0.5, 0, e).ok());
  for (int i = 0; i < 1500; ++i) b.Advance(s.data(), e, 1e-3);
  ASSERT_GT(b.Tension(s.data(), e), 0);
  auto same_block = [](const std::vector<double>& a, const std::vector<double>& c) {
    return std::memcmp(a.data(), c.data(), a.size() * sizeof(double)) == 0;
  };
  // Kept, then taken at the same extension: the same value; the block as before keeping.
  const std::vector<double> before = s;
  const SmaBundle::Summary sum = b.SummarizeAndKeep(s.data(), e);
  EXPECT_TRUE(SameBits(sum.tension, b.Tension(s.data(), e)));
  EXPECT_TRUE(SameBits(b.TakeTension(s.data(), e), b.Tension(s.data(), e)));
  EXPECT_TRUE(same_block(s, before));
  // Taken at another extension: that extension's tension, and nothing stays kept.
  b.SummarizeAndKeep(s.data(), e);
  EXPECT_TRUE(SameBits(b.TakeTension(s.data(), 0.9 * e), b.Tension(s.data(), 0.9 * e)));
  EXPECT_TRUE(same_block(s, before));
  // Nothing kept: computed.
  EXPECT_TRUE(SameBits(b.TakeTension(s.data(), e), b.Tension(s.data(), e)));
  // The units change after keeping: the block is that of the same change without keeping (so
  // nothing stays kept), and TakeTension gives the new tension.
  auto changed = [&](const char* what, auto change) {
    std::vector<double> plain = s;
    b.SummarizeAndKeep(s.data(), e);
    change(s.data());
    change(plain.data());
    EXPECT_TRUE(same_block(s, plain)) << what;
    EXPECT_TRUE(SameBits(b.TakeTension(s.data(), e), b.Tension(plain.data(), e))) << what;
  };
  changed("advance", [&](double* st) { b.Advance(st, e, 1e-3); });
  changed("broadcast", [&](double* st) { ASSERT_TRUE(b.Broadcast(st, 0, 1, e).ok()); });
  changed("reset", [&](double* st) { b.Reset(st, 9, e); });
  // and the advance moved the tension (the kept value would have been wrong)
  const double kept = b.Tension(s.data(), e);
  b.SummarizeAndKeep(s.data(), e);
  ASSERT_TRUE(b.Broadcast(s.data(), 1, 0, e).ok());
  for (int i = 0; i < 1500; ++i) b.Advance(s.data(), e, 1e-3);
  EXPECT_GT(b.TakeTension(s.data(), e), kept + 1);
  EXPECT_TRUE(SameBits(b.TakeTension(s.data(), e), b.Tension(s.data(), e)));
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

}  // namespace file_bundle_test
}  // namespace recruit::sma
