// unit_model=binned against an independent reference: every unit of the bundle advanced on its
// own by the exact scalar update (AdvanceUnitWithDecay, no cohorts, no merging), switched as the
// bundle's broadcasts switched it (UnitOn after each broadcast). The bands and the figures they
// come from are in docs/sma-units.md ("Unit models").
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "plugin/bundle.h"

namespace recruit::sma {
namespace file_unit_model_accuracy_test {

struct Errors {
  double force_units = 0;  // worst |bundle - reference| tension, in units' settled on-tension
  double mean_temp_k = 0;  // worst |bundle - reference| mean temperature, K
  double max_temp_k = 0;   // worst |bundle - reference| hottest unit, K
  double cohorts = 0;      // mean cohorts per step
};

enum class Regime { kFig4Step, kRandomSwitching };

// Runs the bundle `config` (key=value text) for `seconds` at 1 ms steps under the regime and
// returns its errors against the per-unit reference. Random switching: p_on = p_off = 0.1 every
// 0.5 s with the unit extension swinging +-10 % about prestretch over 7 s (a moving limb);
// Fig. 4 step: all on for 10 s, all off for 6 s, isometric.
Errors Compare(const std::string& config, double seconds, Regime regime) {
  auto c = BundleConfig::FromText("test", config);
  EXPECT_TRUE(c.ok()) << c.error();
  const double dt = 1e-3;
  auto b = SmaBundle::Create(*c, dt);
  EXPECT_TRUE(b.ok());
  const UnitModel& m = b->unit();
  const double x0 = c->unit.prestretch;
  std::vector<double> s(b->state_size());
  b->Reset(s.data(), 7, x0);
  const int n = b->num_units();
  std::vector<UnitState> ref(n, RestState(m, x0));
  std::vector<char> on(n, 0);
  const double decay = m.DecayFactor(dt);
  const double unit_force = b->SettledOnTension(x0);
  Errors e;
  const long steps = std::lround(seconds / dt);
  for (long i = 0; i < steps; ++i) {
    const double t = i * dt;
    const double x = regime == Regime::kFig4Step ? x0 : x0 * (1 + 0.1 * std::sin(2 * M_PI * t / 7));
    bool broadcast = false;
    if (regime == Regime::kFig4Step) {
      if (i % 16000 == 0) broadcast = b->Broadcast(s.data(), 1, 0, x).ok();
      if (i % 16000 == 10000) broadcast = b->Broadcast(s.data(), 0, 1, x).ok();
    } else if (i % 500 == 0) {
      broadcast = b->Broadcast(s.data(), 0.1, 0.1, x).ok();
    }
    if (broadcast) {
      for (int u = 0; u < n; ++u) on[u] = b->UnitOn(s.data(), u);
    }
    b->Advance(s.data(), x, dt);
    double force = 0, temp = 0, hottest = -1e9;
    for (int u = 0; u < n; ++u) {
      AdvanceUnitWithDecay(m, ref[u], on[u] != 0, x, decay);
      force += m.Tension(ref[u].xi, x);
      temp += ref[u].temperature;
      hottest = std::max(hottest, ref[u].temperature);
    }
    e.force_units = std::max(e.force_units, std::abs(b->Tension(s.data(), x) - force) / unit_force);
    e.mean_temp_k = std::max(e.mean_temp_k, std::abs(b->MeanTemperature(s.data()) - temp / n));
    e.max_temp_k = std::max(e.max_temp_k, std::abs(b->MaxTemperature(s.data()) - hottest));
    e.cohorts += b->NumCohorts(s.data());
  }
  e.cohorts /= steps;
  if (std::getenv("RECRUIT_PRINT_ACCURACY") != nullptr) {
    std::printf("%-70s %6.0f s: force %.4f units, mean T %.4f K, max T %.3f K, cohorts %.1f\n",
                config.c_str(), seconds, e.force_units, e.mean_temp_k, e.max_temp_k, e.cohorts);
  }
  return e;
}

// MyoSuite's elbow's triceps bundle as `recruit attach` writes it (its largest, 366 units).
const char kElbowUnit[] =
    "units=366 wire_diameter=0.000127 wire_length=0.25 series=4 parallel=3 series_spring=182.687 "
    "prestretch=0.00604701 current=0.2331";

// Figures for docs/sma-units.md: RECRUIT_PRINT_ACCURACY=1 RECRUIT_ACCURACY_MODELS='k=v ...|...'
// prints each model's errors on both bundles.
TEST(UnitModelAccuracy, Explore) {
  if (std::getenv("RECRUIT_PRINT_ACCURACY") == nullptr) GTEST_SKIP();
  const char* env = std::getenv("RECRUIT_ACCURACY_MODELS");
  std::vector<std::string> models;
  for (std::string all = env ? env : ""; !all.empty();) {
    const auto bar = all.find('|');
    models.push_back(all.substr(0, bar));
    all = bar == std::string::npos ? "" : all.substr(bar + 1);
  }
  for (const std::string& model : models) {
    Compare("units=60 " + model, 300, Regime::kRandomSwitching);
    Compare(std::string(kElbowUnit) + " " + model, 100, Regime::kRandomSwitching);
  }
}

// The bands: each model's measured worst error on these runs (docs/sma-units.md), rounded up
// by about half, so that a change that makes a model markedly less accurate fails. The runs
// are deterministic (one seed), so the figures do not scatter.
TEST(UnitModelAccuracy, ExactModelFollowsEveryUnit) {
  const Errors small = Compare("units=60", 300, Regime::kRandomSwitching);
  EXPECT_LE(small.force_units, 0.03);   // measured 0.020
  EXPECT_LE(small.mean_temp_k, 0.015);  // 0.0095
  const Errors elbow = Compare(kElbowUnit, 100, Regime::kRandomSwitching);
  EXPECT_LE(elbow.force_units, 0.5);   // 0.306
  EXPECT_LE(elbow.mean_temp_k, 0.01);  // 0.0055
}

TEST(UnitModelAccuracy, BinnedModelStaysWithinItsBand) {
  const Errors small = Compare("units=60 unit_model=binned bins=16", 300, Regime::kRandomSwitching);
  EXPECT_LE(small.force_units, 1.1);  // measured 0.74
  EXPECT_LE(small.mean_temp_k, 0.5);  // 0.33
  EXPECT_LE(small.cohorts, 16);
  const Errors elbow = Compare(std::string(kElbowUnit) + " unit_model=binned bins=48", 100,
                               Regime::kRandomSwitching);
  EXPECT_LE(elbow.force_units, 8.5);   // 5.6
  EXPECT_LE(elbow.mean_temp_k, 0.13);  // 0.087
  EXPECT_LE(elbow.cohorts, 48);
}

// All units switch together: one cohort, which both models advance by the scalar exact update,
// so the bundle is the reference but for the order of the force's sum.
TEST(UnitModelAccuracy, Fig4StepIsExactInBothModels) {
  for (const std::string model : {"", " unit_model=binned bins=2"}) {
    for (const std::string& units : {std::string("units=60"), std::string(kElbowUnit)}) {
      const Errors e = Compare(units + model, 32, Regime::kFig4Step);
      EXPECT_LE(e.force_units, 1e-9) << units << model;
      EXPECT_LE(e.mean_temp_k, 1e-9) << units << model;
      EXPECT_LE(e.max_temp_k, 1e-9) << units << model;
      EXPECT_EQ(e.cohorts, 1) << units << model;
    }
  }
}

// After each merge pass at most `bins` cohorts; with room for every cohort, binning never merges
// and the bundle is the exact model's, bit for bit.
TEST(UnitModelAccuracy, BinnedBoundsTheCohortsAndIsExactWithRoom) {
  auto run = [](const std::string& text, std::vector<double>* s, int* most_before_broadcast) {
    auto c = BundleConfig::FromText("t", text);
    ASSERT_TRUE(c.ok()) << c.error();
    auto b = SmaBundle::Create(*c, 1e-3);
    ASSERT_TRUE(b.ok());
    s->assign(b->state_size(), 0);
    const double x = c->unit.prestretch;
    b->Reset(s->data(), 11, x);
    *most_before_broadcast = 0;
    for (long i = 0; i < 60000; ++i) {
      if (i % 500 == 0) {
        ASSERT_TRUE(b->Broadcast(s->data(), 0.1, 0.1, x).ok());
      }
      b->Advance(s->data(), x, 1e-3);
      if (i % 500 == 499) {
        *most_before_broadcast = std::max(*most_before_broadcast, b->NumCohorts(s->data()));
      }
    }
  };
  std::vector<double> exact, roomy, binned;
  int k_exact, k_roomy, k_binned;
  run("units=200", &exact, &k_exact);
  run("units=200 unit_model=binned bins=1000000", &roomy, &k_roomy);
  run("units=200 unit_model=binned bins=10", &binned, &k_binned);
  EXPECT_GT(k_exact, 10);
  EXPECT_EQ(k_roomy, k_exact);
  EXPECT_EQ(roomy, exact);  // every double of the block
  EXPECT_EQ(k_binned, 10);
}

// Binning never merges units of different failure modes: after every step each unit's mode is
// the one it failed into (open units never turn on, stuck units stay on) and the counts by mode
// add up, with fatigue's force scales averaged like the rest of the state.
TEST(UnitModelAccuracy, BinnedKeepsFailureModesApart) {
  auto c = BundleConfig::FromText(
      "t",
      "units=80 unit_model=binned bins=4 open_per_cycle=0.05 stuck_per_cycle=0.05 "
      "fatigue_loss=0.2 fatigue_cycles=5");
  ASSERT_TRUE(c.ok()) << c.error();
  auto b = SmaBundle::Create(*c, 1e-3);
  ASSERT_TRUE(b.ok());
  std::vector<double> s(b->state_size());
  const double x = c->unit.prestretch;
  b->Reset(s.data(), 5, x);
  std::vector<int> mode(80, 0);
  for (long i = 0; i < 30000; ++i) {
    if (i % 500 == 0) {
      ASSERT_TRUE(b->Broadcast(s.data(), 0.3, 0.3, x).ok());
    }
    b->Advance(s.data(), x, 1e-3);
    int open = 0, stuck = 0;
    for (int u = 0; u < 80; ++u) {
      const int now = b->UnitFailure(s.data(), u);
      ASSERT_TRUE(mode[u] == 0 || now == mode[u]) << "unit " << u << " step " << i;
      mode[u] = now;
      open += now == 1;
      stuck += now == 2;
      if (now == 1) {
        ASSERT_FALSE(b->UnitOn(s.data(), u));
      }
      if (now == 2) {
        ASSERT_TRUE(b->UnitOn(s.data(), u));
      }
      const double scale = b->UnitForceScale(s.data(), u);
      ASSERT_TRUE(scale >= 0.8 && scale <= 1) << scale;
    }
    const auto f = b->Failures(s.data());
    ASSERT_EQ(f.open, open);
    ASSERT_EQ(f.stuck, stuck);
    ASSERT_EQ(f.working + f.open + f.stuck, 80);
  }
  const auto f = b->Failures(s.data());
  EXPECT_GT(f.open, 0);
  EXPECT_GT(f.stuck, 0);
  EXPECT_GT(f.working, 0);
}

}  // namespace file_unit_model_accuracy_test
}  // namespace recruit::sma
