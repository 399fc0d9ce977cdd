// The batched cohort update (UnitModel::AdvanceCohorts, SIMD lanes, structure of arrays) against
// the scalar per-cohort update it replaces in the bundle (AdvanceUnitWithDecay, kept as the
// reference): bit-identical results, cohort by cohort, for random states and along trajectories
// with random switching, across unit models and cohort counts that leave partial SIMD batches and
// span several 64-cohort chunks; for the build's own kernel and the AVX2 and AVX-512 clones.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <functional>
#include <string>
#include <tuple>
#include <vector>

#include "common/rng.h"
#include "plugin/bundle_config.h"
#include "plugin/unit_model.h"

namespace recruit::sma {
namespace file_cohort_batch_test {

UnitModel MakeModel(const std::string& text) {
  auto c = BundleConfig::FromText("b", text);
  EXPECT_TRUE(c.ok()) << c.error();
  auto m = UnitModel::Create(c->unit);
  EXPECT_TRUE(m.ok()) << m.error();
  return m.value();
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Structure-of-arrays cohorts, as the bundle lays them out.
struct Soa {
  std::vector<double> on, temperature, xi, t_eff, heat_scale, cool_scale;
  explicit Soa(int n) : on(n), temperature(n), xi(n), t_eff(n), heat_scale(n), cool_scale(n) {}
  UnitModel::Cohorts View() {
    return {on.data(),    temperature.data(), xi.data(),
            t_eff.data(), heat_scale.data(),  cool_scale.data()};
  }
  UnitState Get(int j) const {
    return {temperature[j], xi[j], t_eff[j], heat_scale[j], cool_scale[j]};
  }
  void Set(int j, const UnitState& s) {
    temperature[j] = s.temperature;
    xi[j] = s.xi;
    t_eff[j] = s.t_eff;
    heat_scale[j] = s.heat_scale;
    cool_scale[j] = s.cool_scale;
  }
};

// One batched step against the scalar step of every cohort; reports the first difference.
::testing::AssertionResult StepMatchesScalar(const UnitModel& m, Soa& soa, double stretch,
                                             double decay, UnitModel::Isa isa) {
  const int n = static_cast<int>(soa.on.size());
  std::vector<UnitState> ref(n);
  for (int j = 0; j < n; ++j) {
    ref[j] = soa.Get(j);
    AdvanceUnitWithDecay(m, ref[j], soa.on[j] != 0, stretch, decay);
  }
  m.AdvanceCohorts(soa.View(), n, stretch, decay, isa);
  for (int j = 0; j < n; ++j) {
    const UnitState b = soa.Get(j);
    if (!SameBits(b.temperature, ref[j].temperature) || !SameBits(b.xi, ref[j].xi) ||
        !SameBits(b.t_eff, ref[j].t_eff) || !SameBits(b.heat_scale, ref[j].heat_scale) ||
        !SameBits(b.cool_scale, ref[j].cool_scale)) {
      return ::testing::AssertionFailure()
             << "cohort " << j << " of " << n << ": batched (T " << b.temperature << ", xi " << b.xi
             << ", T_eff " << b.t_eff << ", hs " << b.heat_scale << ", cs " << b.cool_scale
             << ") scalar (" << ref[j].temperature << ", " << ref[j].xi << ", " << ref[j].t_eff
             << ", " << ref[j].heat_scale << ", " << ref[j].cool_scale << ")";
    }
  }
  return ::testing::AssertionSuccess();
}

class BatchedCohorts : public ::testing::TestWithParam<std::tuple<std::string, UnitModel::Isa>> {
 protected:
  void SetUp() override {
    if (isa() == UnitModel::Isa::kAvx2 && !UnitModel::HasAvx2()) {
      GTEST_SKIP() << "no AVX2 kernel in this build or CPU";
    }
    if (isa() == UnitModel::Isa::kAvx512 && !UnitModel::HasAvx512()) {
      GTEST_SKIP() << "no AVX-512 kernel in this build or CPU";
    }
  }
  const std::string& config() const { return std::get<0>(GetParam()); }
  UnitModel::Isa isa() const { return std::get<1>(GetParam()); }
};

// Random states anywhere in and around the loop: ends (0, 1, within 1e-12 of them), inside the
// transformation windows, above and below them, heating or cooling relative to T_eff.
TEST_P(BatchedCohorts, RandomStatesAreBitIdenticalToScalarUpdate) {
  const UnitModel m = MakeModel(config());
  const double e0 = m.params().prestretch;
  Rng rng(2024);
  int transforming = 0;
  for (int n : {1, 2, 3, 4, 5, 7, 63, 64, 65, 131}) {
    for (int trial = 0; trial < 40; ++trial) {
      Soa soa(n);
      for (int j = 0; j < n; ++j) {
        soa.on[j] = rng.Uniform() < 0.5 ? 1 : 0;
        soa.temperature[j] = 15 + 130 * rng.Uniform();
        const double u = rng.Uniform();
        soa.xi[j] = u < 0.2    ? 1
                    : u < 0.4  ? 0
                    : u < 0.45 ? 1 - 1e-13
                    : u < 0.5  ? 1e-13
                               : rng.Uniform();
        soa.t_eff[j] = soa.temperature[j] + 20 * (rng.Uniform() - 0.5);
        soa.heat_scale[j] = rng.Uniform() < 0.3 ? 1 : rng.Uniform();
        soa.cool_scale[j] = rng.Uniform() < 0.3 ? 1 : rng.Uniform();
      }
      const double stretch = 1.5 * e0 * rng.Uniform();
      const double dt = trial % 3 == 0 ? 1e-3 : trial % 3 == 1 ? 1e-2 : 0.3;
      const std::vector<double> xi_before = soa.xi;
      ASSERT_TRUE(StepMatchesScalar(m, soa, stretch, m.DecayFactor(dt), isa()))
          << "n " << n << " trial " << trial;
      for (int j = 0; j < n; ++j) transforming += soa.xi[j] != xi_before[j];
    }
  }
  EXPECT_GT(transforming, 1000);  // the phase solves ran, not just the thermal step
}

// Trajectories: 70 cohorts switched at random every 0.3 s for 30 s, batched and scalar updates
// compared after every step (states stay on the physical loop, minor loops included).
TEST_P(BatchedCohorts, SwitchingTrajectoriesAreBitIdenticalToScalarUpdate) {
  const UnitModel m = MakeModel(config());
  const double stretch = m.params().prestretch;
  const int n = 70;
  Soa soa(n);
  const UnitState rest = RestState(m, stretch);
  for (int j = 0; j < n; ++j) soa.Set(j, rest);
  Rng rng(7);
  const double decay = m.DecayFactor(1e-3);
  int solved_steps = 0;
  for (int step = 0; step < 30000; ++step) {
    if (step % 300 == 0) {
      for (int j = 0; j < n; ++j) {
        if (rng.Uniform() < 0.3) soa.on[j] = soa.on[j] != 0 ? 0 : 1;
      }
    }
    const std::vector<double> xi_before = soa.xi;
    ASSERT_TRUE(StepMatchesScalar(m, soa, stretch, decay, isa())) << "step " << step;
    solved_steps += soa.xi != xi_before;
  }
  EXPECT_GT(solved_steps, 10000);
}

// Cohorts at rest and off, which do not change, or on and hot inside the heating window, whose
// xi falls: Step(n, transforms) sets cohort j hot where transforms(j), advances all n by one
// batched step, and checks it against the scalar update and that exactly those cohorts moved.
struct StillOrHot {
  explicit StillOrHot(const UnitModel& model)
      : m(model), stretch(m.params().prestretch), decay(m.DecayFactor(1e-3)) {
    still = RestState(m, stretch);
    hot = still;
    hot.temperature = m.params().Af + 5;
  }
  ::testing::AssertionResult Step(int n, const std::function<bool(int)>& transforms,
                                  UnitModel::Isa isa) const {
    Soa soa(n);
    for (int j = 0; j < n; ++j) {
      soa.on[j] = transforms(j) ? 1 : 0;
      soa.Set(j, transforms(j) ? hot : still);
    }
    const std::vector<double> xi_before = soa.xi;
    if (!StepMatchesScalar(m, soa, stretch, decay, isa)) {
      return ::testing::AssertionFailure() << "not the scalar update";
    }
    for (int j = 0; j < n; ++j) {
      if ((soa.xi[j] != xi_before[j]) != transforms(j)) {
        return ::testing::AssertionFailure()
               << "cohort " << j << (transforms(j) ? " not" : "") << " solved";
      }
    }
    return ::testing::AssertionSuccess();
  }
  const UnitModel& m;
  double stretch, decay;
  UnitState still, hot;
};

// Every pattern of transforming lanes in a SIMD batch (a cohort of each 8-cohort group
// transforms where the group's bit is set, all 256 patterns; 2, 4 and 8 lanes divide 8), then a
// partial tail: each transforming cohort is solved, and only those.
TEST_P(BatchedCohorts, EveryPatternOfTransformingLanesIsSolved) {
  const UnitModel m = MakeModel(config());
  const StillOrHot cohorts(m);
  UnitState a = cohorts.still, b = cohorts.hot;
  AdvanceUnitWithDecay(m, a, false, cohorts.stretch, cohorts.decay);
  AdvanceUnitWithDecay(m, b, true, cohorts.stretch, cohorts.decay);
  ASSERT_EQ(a.xi, cohorts.still.xi);
  ASSERT_NE(b.xi, cohorts.hot.xi);
  for (int n : {8 * 256, 8 * 256 + 5}) {
    EXPECT_TRUE(cohorts.Step(
        n, [](int j) { return (((j / 8) >> (j % 8)) & 1) != 0 || j >= 8 * 256; }, isa()))
        << "n " << n;
  }
}

// At most a batch of cohorts (an arm's bundle has about four), solved where they are: for each
// count from 1 to 8 every pattern of transforming cohorts is solved, and only those.
TEST_P(BatchedCohorts, EveryPatternOfTransformingCohortsInOneBatchIsSolved) {
  const UnitModel m = MakeModel(config());
  const StillOrHot cohorts(m);
  for (int n = 1; n <= 8; ++n) {
    for (int pattern = 0; pattern < (1 << n); ++pattern) {
      ASSERT_TRUE(cohorts.Step(
          n, [pattern](int j) { return ((pattern >> j) & 1) != 0; }, isa()))
          << "n " << n << " pattern " << pattern;
    }
  }
}

// The update with its telemetry (BatchObserve): the same cohorts, bit for bit, as without it, and
// when the kernel gives the telemetry (cohorts that fit one SIMD block), SumTelemetry's five
// values at the observed extension and the largest temperature, bit for bit.
TEST_P(BatchedCohorts, ObservedUpdateGivesTheSeparatePassValuesBitForBit) {
  const UnitModel m = MakeModel(config());
  const double e0 = m.params().prestretch;
  Rng rng(77);
  int given = 0;
  for (int n : {1, 2, 3, 4, 5, 6, 7, 8, 9, 65}) {
    for (int trial = 0; trial < 60; ++trial) {
      Soa soa(n);
      std::vector<double> count(n);
      for (int j = 0; j < n; ++j) {
        count[j] = 1 + static_cast<int>(20 * rng.Uniform());
        soa.on[j] = rng.Uniform() < 0.5 ? 1 : 0;
        soa.temperature[j] = 15 + 130 * rng.Uniform();
        soa.xi[j] = rng.Uniform() < 0.3 ? 1 : rng.Uniform() < 0.3 ? 0 : rng.Uniform();
        soa.t_eff[j] = soa.temperature[j] + 20 * (rng.Uniform() - 0.5);
        soa.heat_scale[j] = rng.Uniform() < 0.3 ? 1 : rng.Uniform();
        soa.cool_scale[j] = rng.Uniform() < 0.3 ? 1 : rng.Uniform();
      }
      Soa plain = soa;
      const double stretch = 1.5 * e0 * rng.Uniform();
      // Sometimes the same extension, sometimes another (slack ones included).
      const double seen = trial % 4 == 0 ? stretch : 1.5 * e0 * rng.Uniform() - 0.1 * e0;
      const double decay = m.DecayFactor(trial % 2 == 0 ? 1e-3 : 0.05);
      BatchObserve obs;
      obs.count = count.data();
      obs.stretch = seen;
      for (double& x : obs.out) x = -7;
      m.AdvanceCohorts(soa.View(), n, stretch, decay, isa(), &obs);
      m.AdvanceCohorts(plain.View(), n, stretch, decay, isa());
      const std::string where = "n " + std::to_string(n) + " trial " + std::to_string(trial);
      for (int j = 0; j < n; ++j) {
        ASSERT_TRUE(SameBits(soa.temperature[j], plain.temperature[j]) &&
                    SameBits(soa.xi[j], plain.xi[j]) && SameBits(soa.t_eff[j], plain.t_eff[j]) &&
                    SameBits(soa.heat_scale[j], plain.heat_scale[j]) &&
                    SameBits(soa.cool_scale[j], plain.cool_scale[j]))
            << where << " cohort " << j;
      }
      if (!obs.done) continue;
      ++given;
      const double* v[3] = {plain.on.data(), plain.temperature.data(), plain.xi.data()};
      double ref[5];
      m.SumTelemetry(count.data(), v, n, seen, true, ref);  // the run loop's separate pass
      for (int f = 0; f < 5; ++f) {
        EXPECT_TRUE(SameBits(obs.out[f], ref[f]))
            << where << " value " << f << ": " << obs.out[f] << " vs " << ref[f];
      }
      double hottest = plain.temperature[0];
      for (int j = 1; j < n; ++j) hottest = std::max(hottest, plain.temperature[j]);
      EXPECT_TRUE(SameBits(obs.out[5], hottest)) << where;
    }
  }
  // One block: up to 4 cohorts with AVX2 (the portable build: 2 or 4); one cohort takes the
  // scalar update only under kAuto. The AVX-512 update gives none (UnitModel::Update).
  if (isa() == UnitModel::Isa::kAvx512) {
    EXPECT_EQ(given, 0);
  } else {
    EXPECT_GE(given, 2 * 60);
  }
}

// More cohorts than one SIMD block holds but at most two (5-8 with AVX2, 3-4 with the portable
// SSE2 kernel, 9-16 with AVX-512), the count a bundle switched a few units at a time keeps: the
// update solves both blocks where they are. Random states and random switching trajectories
// against the scalar update of every cohort, and the telemetry the update gives on its way
// against a plain scalar sum in the kernels' order (partial sum j mod 4, added as
// (s0 + s1) + (s2 + s3)) of count * (on, T, xi, UnitModel::Tension at the observed extension),
// and plain maxima of Tension and T.
// Under kAuto one cohort more than a block (5 with AVX2) has its last cohort updated by the scalar
// update and the block by the kernel, the telemetry of both folded as for two blocks.
void CheckTwoBlocks(const std::string& config, UnitModel::Isa isa) {
  const UnitModel m = MakeModel(config);
  const double e0 = m.params().prestretch;
  const int lanes = UnitModel::Lanes(isa);
  Rng rng(2029);
  int given = 0, trials = 0, moved[2] = {0, 0};
  for (int n = lanes + 1; n <= 2 * lanes; ++n) {
    Soa soa(n);
    std::vector<double> count(n);
    for (int trial = 0; trial < 400; ++trial) {
      // A fresh random state every 50 steps; otherwise the last step's cohorts, switched at random
      // (minor loops, cohorts in and out of the transformation windows).
      for (int j = 0; j < n; ++j) {
        if (trial % 50 == 0) {
          count[j] = 1 + static_cast<int>(20 * rng.Uniform());
          soa.temperature[j] = 15 + 130 * rng.Uniform();
          const double u = rng.Uniform();
          soa.xi[j] = u < 0.2 ? 1 : u < 0.4 ? 0 : u < 0.45 ? 1 - 1e-13 : rng.Uniform();
          soa.t_eff[j] = soa.temperature[j] + 20 * (rng.Uniform() - 0.5);
          soa.heat_scale[j] = rng.Uniform() < 0.3 ? 1 : rng.Uniform();
          soa.cool_scale[j] = rng.Uniform() < 0.3 ? 1 : rng.Uniform();
        }
        if (trial % 50 == 0 || rng.Uniform() < 0.05) soa.on[j] = rng.Uniform() < 0.5 ? 1 : 0;
      }
      const double stretch = e0 * (0.5 + rng.Uniform());
      const double seen = trial % 3 == 0 ? stretch : 1.5 * e0 * rng.Uniform() - 0.1 * e0;
      const double decay = m.DecayFactor(trial % 2 == 0 ? 1e-3 : 0.02);
      const std::string where = "n " + std::to_string(n) + " trial " + std::to_string(trial);
      std::vector<UnitState> ref(n);
      for (int j = 0; j < n; ++j) {
        ref[j] = soa.Get(j);
        AdvanceUnitWithDecay(m, ref[j], soa.on[j] != 0, stretch, decay);
      }
      const std::vector<double> xi_before = soa.xi;
      BatchObserve obs;
      obs.count = count.data();
      obs.stretch = seen;
      for (double& x : obs.out) x = -7;
      m.AdvanceCohorts(soa.View(), n, stretch, decay, isa, &obs);
      ++trials;
      for (int j = 0; j < n; ++j) {
        const UnitState b = soa.Get(j);
        ASSERT_TRUE(SameBits(b.temperature, ref[j].temperature) && SameBits(b.xi, ref[j].xi) &&
                    SameBits(b.t_eff, ref[j].t_eff) && SameBits(b.heat_scale, ref[j].heat_scale) &&
                    SameBits(b.cool_scale, ref[j].cool_scale))
            << where << " cohort " << j;
        moved[j < lanes ? 0 : 1] += soa.xi[j] != xi_before[j];
      }
      if (!obs.done) continue;
      ++given;
      double s[4][4] = {};
      double peak = 0, hottest = soa.temperature[0];
      for (int j = 0; j < n; ++j) {
        const double t = m.Tension(soa.xi[j], seen);
        const double terms[4] = {count[j] * soa.on[j], count[j] * soa.temperature[j],
                                 count[j] * soa.xi[j], count[j] * t};
        for (int f = 0; f < 4; ++f) s[f][j % 4] += terms[f];
        peak = std::max(peak, t);
        hottest = std::max(hottest, soa.temperature[j]);
      }
      for (int f = 0; f < 4; ++f) {
        const double sum = (s[f][0] + s[f][1]) + (s[f][2] + s[f][3]);
        EXPECT_TRUE(SameBits(obs.out[f], sum))
            << where << " value " << f << ": " << obs.out[f] << " vs " << sum;
      }
      EXPECT_TRUE(SameBits(obs.out[4], peak)) << where << ": " << obs.out[4] << " vs " << peak;
      EXPECT_TRUE(SameBits(obs.out[5], hottest)) << where;
    }
  }
  EXPECT_GT(moved[0], trials / 8);  // the phase solves ran, in both blocks
  EXPECT_GT(moved[1], trials / 8);
  // The AVX-512 update gives no telemetry (UnitModel::Update); the others always do here.
  const bool avx512 =
      isa == UnitModel::Isa::kAvx512 || (isa == UnitModel::Isa::kAuto && UnitModel::HasAvx512());
  EXPECT_EQ(given, avx512 ? 0 : trials);
}

TEST_P(BatchedCohorts, TwoBlocksOfCohortsAreTheScalarUpdateAndTheScalarSums) {
  CheckTwoBlocks(config(), isa());
}

TEST(BatchedCohortsAuto, TwoBlocksOfCohortsAreTheScalarUpdateAndTheScalarSums) {
  for (const char* config : {"", "series_spring=0", "law=spring current=0.235",
                             "parallel=2 series=3", "latent_heat=0"}) {
    SCOPED_TRACE(config);
    CheckTwoBlocks(config, UnitModel::Isa::kAuto);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Units, BatchedCohorts,
    ::testing::Combine(::testing::Values("",                          // datasheet wire unit
                                         "series_spring=0",           // rigid: no series spring
                                         "law=spring current=0.235",  // coiled spring
                                         "parallel=2 series=3", "latent_heat=0"),
                       ::testing::Values(UnitModel::Isa::kBase, UnitModel::Isa::kAvx2,
                                         UnitModel::Isa::kAvx512)));

// One cohort (units switched together) takes the scalar update under kAuto; asked for its
// telemetry it gives SumTelemetry's values for that cohort (the run loop's separate pass) and its
// temperature, bit for bit, from the values it computed: random states, taut and slack.
TEST(BatchedCohorts, OneCohortsObservedUpdateGivesTheSeparatePassValues) {
  for (const char* config : {"", "series_spring=0", "law=spring current=0.235"}) {
    const UnitModel m = MakeModel(config);
    const double e0 = m.params().prestretch;
    Rng rng(31);
    for (int trial = 0; trial < 500; ++trial) {
      Soa soa(1);
      double count = 1 + static_cast<int>(50 * rng.Uniform());
      soa.on[0] = rng.Uniform() < 0.5 ? 1 : 0;
      soa.temperature[0] = 15 + 130 * rng.Uniform();
      soa.xi[0] = rng.Uniform() < 0.3 ? 1 : rng.Uniform() < 0.3 ? 0 : rng.Uniform();
      soa.t_eff[0] = soa.temperature[0] + 20 * (rng.Uniform() - 0.5);
      soa.heat_scale[0] = rng.Uniform() < 0.3 ? 1 : rng.Uniform();
      soa.cool_scale[0] = rng.Uniform() < 0.3 ? 1 : rng.Uniform();
      const double stretch = 1.5 * e0 * rng.Uniform();
      const double seen = trial % 4 == 0 ? stretch : 1.5 * e0 * rng.Uniform() - 0.1 * e0;
      UnitState ref = soa.Get(0);
      AdvanceUnitWithDecay(m, ref, soa.on[0] != 0, stretch, m.DecayFactor(1e-3));
      BatchObserve obs;
      obs.count = &count;
      obs.stretch = seen;
      m.AdvanceCohorts(soa.View(), 1, stretch, m.DecayFactor(1e-3), UnitModel::Isa::kAuto, &obs);
      const UnitState b = soa.Get(0);
      ASSERT_TRUE(SameBits(b.temperature, ref.temperature) && SameBits(b.xi, ref.xi) &&
                  SameBits(b.t_eff, ref.t_eff) && SameBits(b.heat_scale, ref.heat_scale) &&
                  SameBits(b.cool_scale, ref.cool_scale))
          << config << " trial " << trial;
      ASSERT_TRUE(obs.done);
      const double* v[3] = {soa.on.data(), soa.temperature.data(), soa.xi.data()};
      double sep[5];
      m.SumTelemetry(&count, v, 1, seen, true, sep);
      for (int f = 0; f < 5; ++f) {
        EXPECT_TRUE(SameBits(obs.out[f], sep[f])) << config << " trial " << trial << " f " << f;
      }
      EXPECT_TRUE(SameBits(obs.out[3], count * m.Tension(b.xi, seen)));
      EXPECT_TRUE(SameBits(obs.out[5], b.temperature));
    }
  }
}

// The tension sum over cohorts against the scalar sum of count * Tension: the same to rounding
// of the summation order (four partial sums), exactly for one cohort.
TEST(BatchedCohortSums, SumTensionMatchesScalarSum) {
  const UnitModel m = MakeModel("");
  std::vector<UnitModel::Isa> isas = {UnitModel::Isa::kBase};
  if (UnitModel::HasAvx2()) isas.push_back(UnitModel::Isa::kAvx2);
  Rng rng(3);
  for (int n : {1, 2, 3, 5, 8, 33, 300}) {
    std::vector<double> count(n), xi(n);
    for (int j = 0; j < n; ++j) {
      count[j] = 1 + static_cast<int>(10 * rng.Uniform());
      xi[j] = rng.Uniform() < 0.3 ? 1 : rng.Uniform();
    }
    for (double stretch : {0.0, 1e-3, 4e-3, 6e-3}) {
      double ref = 0;
      for (int j = 0; j < n; ++j) ref += count[j] * m.Tension(xi[j], stretch);
      for (UnitModel::Isa isa : isas) {
        const double got = m.SumTension(count.data(), xi.data(), n, stretch, isa);
        if (n == 1) {
          EXPECT_TRUE(SameBits(got, ref)) << got << " vs " << ref;
        } else {
          EXPECT_NEAR(got, ref, 1e-14 * (1 + ref)) << "n " << n << " stretch " << stretch;
        }
      }
    }
  }
}

// SumTelemetry (the sensor's and the run loop's one pass) against the separate kernels it fuses:
// WeightedSums of (on, T, xi) and SumTension bit for bit, and the largest tension against a
// plain scalar maximum of UnitModel::Tension; every cohort count around the SIMD widths, slack
// and taut extensions, each kernel.
TEST(BatchedCohortSums, ObserveEqualsTheSeparateSumsAndTheScalarMaximum) {
  const UnitModel m = MakeModel("");
  std::vector<UnitModel::Isa> isas = {UnitModel::Isa::kAuto, UnitModel::Isa::kBase};
  if (UnitModel::HasAvx2()) isas.push_back(UnitModel::Isa::kAvx2);
  Rng rng(11);
  for (int n : {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 33, 300}) {
    std::vector<double> count(n), on(n), temperature(n), xi(n);
    for (int j = 0; j < n; ++j) {
      count[j] = 1 + static_cast<int>(10 * rng.Uniform());
      on[j] = rng.Uniform() < 0.5 ? 1 : 0;
      temperature[j] = 20 + 100 * rng.Uniform();
      xi[j] = rng.Uniform() < 0.3 ? 1 : rng.Uniform();
    }
    const double* v[3] = {on.data(), temperature.data(), xi.data()};
    double sums[3];
    UnitModel::WeightedSums(count.data(), v, 3, n, sums);
    for (double stretch : {0.0, 1e-3, 4e-3, 6e-3}) {
      double top = 0;
      for (int j = 0; j < n; ++j) top = std::max(top, m.Tension(xi[j], stretch));
      for (UnitModel::Isa isa : isas) {
        const double tension = m.SumTension(count.data(), xi.data(), n, stretch, isa);
        for (bool peak : {false, true}) {
          double out[5] = {-1, -1, -1, -1, -1};
          m.SumTelemetry(count.data(), v, n, stretch, peak, out, isa);
          const std::string where = "n " + std::to_string(n) + " stretch " +
                                    std::to_string(stretch) + " isa " +
                                    std::to_string(static_cast<int>(isa));
          for (int f = 0; f < 3; ++f) EXPECT_TRUE(SameBits(out[f], sums[f])) << where << " f " << f;
          EXPECT_TRUE(SameBits(out[3], tension)) << where << ": " << out[3] << " vs " << tension;
          if (peak) {
            EXPECT_TRUE(SameBits(out[4], top)) << where << ": " << out[4] << " vs " << top;
          } else {
            EXPECT_EQ(out[4], -1) << where;  // not written
          }
        }
      }
    }
  }
}

// The merge pass's order without a sort (MergeOrder) against std::sort with the merge's
// comparator: the same permutation whenever it answers; it answers for distinct keys and gives
// up on ties (equal temperatures, +0 and -0), NaN and on values other than 0 and 1, where the
// merge sorts as before. Each kernel, cohort counts around the SIMD widths, up to the 320 cohorts
// the merge asks it for.
TEST(MergeOrder, IsStdSortsOrderForDistinctKeysAndGivesUpOnTies) {
  std::vector<UnitModel::Isa> isas = {UnitModel::Isa::kAuto, UnitModel::Isa::kBase};
  if (UnitModel::HasAvx2()) isas.push_back(UnitModel::Isa::kAvx2);
  if (UnitModel::HasAvx512()) isas.push_back(UnitModel::Isa::kAvx512);
  Rng rng(5);
  auto sorted = [](const std::vector<double>& on, const std::vector<double>& t) {
    std::vector<int> idx(on.size());
    for (size_t j = 0; j < idx.size(); ++j) idx[j] = static_cast<int>(j);
    std::sort(idx.begin(), idx.end(), [&](int a, int b) {
      if (on[a] != on[b]) return on[a] < on[b];
      return t[a] < t[b];
    });
    return idx;
  };
  int answered = 0, gave_up = 0;
  // Every count up to 64, then counts around the SIMD widths up to and past the merge's limit
  // (320).
  std::vector<int> counts;
  for (int n = 1; n <= 64; ++n) counts.push_back(n);
  for (int n : {65, 67, 100, 127, 128, 129, 255, 256, 257, 300, 319, 320, 321, 512})
    counts.push_back(n);
  for (int n : counts) {
    for (int trial = 0; trial < 20; ++trial) {
      std::vector<double> on(n), t(n);
      for (int j = 0; j < n; ++j) {
        on[j] = rng.Uniform() < 0.5 ? 1 : 0;
        t[j] = 20 + 100 * rng.Uniform();
      }
      const int kind = trial % 5;  // 0, 1: distinct; 2: a tie; 3: NaN; 4: on = 0.5
      const int a = static_cast<int>(n * rng.Uniform()), b = (a + 1) % n;
      if (kind == 2 && n > 1) on[b] = on[a], t[b] = t[a];
      if (kind == 2 && n > 1 && trial % 10 == 7) t[a] = 0.0, t[b] = -0.0;  // +0 and -0 tie
      if (kind == 3) t[a] = std::nan("");
      if (kind == 4) on[a] = 0.5;
      const bool tie = kind == 2 && n > 1;
      const bool distinct = kind < 2 || (kind == 2 && n == 1);
      const std::vector<int> want = sorted(on, t);
      for (UnitModel::Isa isa : isas) {
        std::vector<int> order(n, -7), idx(2 * n + 16);
        std::vector<double> scratch(2 * n + 16);
        const bool ok = UnitModel::MergeOrder(on.data(), t.data(), n, order.data(), scratch.data(),
                                              idx.data(), isa);
        if (distinct) {
          EXPECT_TRUE(ok) << "n " << n << " trial " << trial;
          EXPECT_EQ(order, want) << "n " << n << " trial " << trial;
        } else if (tie || kind == 3 || kind == 4) {
          EXPECT_FALSE(ok) << "n " << n << " trial " << trial << " kind " << kind;
        }
        (ok ? answered : gave_up) += 1;
      }
    }
  }
  EXPECT_GT(answered, 1000);
  EXPECT_GT(gave_up, 1000);
}

}  // namespace file_cohort_batch_test
}  // namespace recruit::sma
