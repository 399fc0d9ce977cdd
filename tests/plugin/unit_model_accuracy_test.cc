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
namespace {

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

TEST(UnitModelAccuracy, Explore) {
  if (std::getenv("RECRUIT_PRINT_ACCURACY") == nullptr) GTEST_SKIP();
  const char* env = std::getenv("RECRUIT_ACCURACY_MODELS");
  std::vector<std::string> models;
  for (std::string all = env ? env : "", item; !all.empty();) {
    const auto bar = all.find('|');
    models.push_back(all.substr(0, bar));
    all = bar == std::string::npos ? "" : all.substr(bar + 1);
  }
  for (const std::string& model : models) {
    Compare(std::string("units=60 ") + model, 300, Regime::kRandomSwitching);
    Compare(std::string(kElbowUnit) + " " + model, 100, Regime::kRandomSwitching);
  }
}

}  // namespace
}  // namespace recruit::sma
