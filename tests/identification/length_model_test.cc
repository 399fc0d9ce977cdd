// The length-dependent output model end to end on synthetic plants whose truth is known: the
// identification at the longest tendon recovers each state's martensite fraction (and so its
// force at any other length), and the length-aware Kalman filter on a plant that matches its
// model exactly, with the tendon length moving, is consistent: its on-count NEES is within the
// chi-square band (a filter with H fixed at the reference length is not).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "common/rng.h"
#include "control/kalman_estimator.h"
#include "control/unit_force_map.h"
#include "estimation/population_chain.h"
#include "identification/excitation.h"
#include "identification/identification.h"
#include "identification/model_export.h"
#include "identification/transient_chain.h"

namespace recruit::identification {
namespace file_length_model_test {

using namespace ::recruit::control;  // NOLINT: the controller side these tests check against

// K = 3 (m = 8): cold, heat1..3, hot, cool1..3, with a fraction per state.
TransientChain KnownChain() {
  TransientChain c = TransientChain::Uniform(8, 1.0);
  c.heat_advance << 1.0, 0.6, 0.4;
  c.cool_advance << 0.8, 0.5, 0.3;
  return c;
}
Eigen::VectorXd KnownFractions() {
  Eigen::VectorXd xi(8);
  xi << 1.0, 0.9, 0.55, 0.2, 0.0, 0.1, 0.45, 0.85;
  return xi;
}
UnitGeometry Geometry() {
  UnitGeometry g;  // the plugin's default unit: 0.1 mm wire, 4 mm stroke, 114 N/m spring
  g.ref_length = 0.25;
  return g;
}

double Gaussian(Rng& rng) {
  const double u1 = std::max(rng.Uniform(), 1e-300), u2 = rng.Uniform();
  return std::sqrt(-2 * std::log(u1)) * std::cos(2 * M_PI * u2);
}

// A population of `units` on the chain (the estimation part's exact aggregate sampler), its
// tendon at length(k), force = sum over states of count x force law at the state's fraction,
// plus sensor noise.
struct SyntheticRun {
  SwitchingLog log;
  std::vector<double> length, true_on;
};
template <class LengthFn>
SyntheticRun Simulate(const TransientChain& c, const UnitForceMap& map, int units, int samples,
                      double noise_std, std::uint64_t seed, LengthFn length) {
  SyntheticRun run;
  run.log.num_units = units;
  run.log.dT = 0.5;
  const Excitation e = MakeExcitation(8, samples, seed);
  Rng rng(seed + 1);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(c.num_states());
  x[c.cold()] = units;
  Eigen::RowVectorXd h(c.num_states());
  const auto is_on = c.IsOn();
  for (int k = 0; k < samples; ++k) {
    const double L = length(k);
    map.Forces(L, h);
    double on = 0;
    for (int s = 0; s < c.num_states(); ++s) on += is_on[s] ? x[s] : 0.0;
    run.log.time.push_back(k * run.log.dT);
    run.log.force.push_back(h.dot(x) + noise_std * Gaussian(rng));
    run.log.p_on.push_back(e.p_on[k]);
    run.log.p_off.push_back(e.p_off[k]);
    run.length.push_back(L);
    run.true_on.push_back(on);
    x = estimation::SimulateStepAggregate(c.Matrix(e.p_on[k], e.p_off[k]), x, rng);
  }
  return run;
}

TEST(LengthModel, IdentificationAtTheLongestTendonRecoversEveryStatesFraction) {
  const UnitGeometry g = Geometry();
  auto truth = UnitForceMap::FromFractions(g, KnownFractions());
  ASSERT_TRUE(truth.ok()) << truth.error();
  // The longest tendon: the unit extended by its whole stroke, where every state is taut.
  const double stroke = truth->unit().recoverable_stretch();
  const double longest = g.ref_length + (stroke - g.unit.prestretch);
  const SyntheticRun run =
      Simulate(KnownChain(), *truth, 50000, 1500, 0.5, 7, [&](int) { return longest; });
  FitOptions opt;
  opt.num_states = 8;
  opt.smoothness = 1e-6;
  opt.fit_noise = false;  // the forces are what is checked
  auto fit = IdentifyTransientModel(run.log, opt);
  ASSERT_TRUE(fit.ok()) << fit.error();
  auto found = UnitForceMap::FromForces(g, truth->Stretch(longest), fit->chain.force);
  ASSERT_TRUE(found.ok()) << found.error();
  // Fractions within 0.03 (the forces within 0.01 N of 0.45 N, as in the fixed-length test),
  // and so the forces at a tendon 2 mm shorter, where the fit saw nothing, within 0.012 N.
  for (int s = 0; s < 8; ++s) {
    EXPECT_NEAR(found->fractions()[s], KnownFractions()[s], 0.03) << s;
    EXPECT_NEAR(found->Force(s, longest - 0.002), truth->Force(s, longest - 0.002), 0.012) << s;
  }
}

// Mean on-count NEES at instants 400, 500 and 600 (in the random switching) over 400 independent
// runs of 60 units, the tendon moving +-1.5 mm around its reference (period 20 s) while the
// broadcasts excite the chain. For a consistent filter each NEES is chi-square with 1 dof: the mean
// of 400 is within 1 +- 3 sqrt(2 / 400) = [0.79, 1.21] (3 sigma).
std::vector<double> MeanNees(bool length_aware) {
  const UnitGeometry g = Geometry();
  auto map = UnitForceMap::FromFractions(g, KnownFractions());
  EXPECT_TRUE(map.ok());
  TransientChain c = KnownChain();
  c.force.resize(8);
  map->Forces(g.ref_length, c.force);
  const double noise = 0.05;
  const estimation::FilterModel model = ToFilterModel(c, 60, 0.5, noise * noise);
  const std::vector<int> at = {400, 500, 600};
  std::vector<double> sum(at.size(), 0.0);
  const int runs = 400;
  for (int r = 0; r < runs; ++r) {
    auto length = [&](int k) { return g.ref_length + 0.0015 * std::sin(2 * M_PI * k / 40.0); };
    const SyntheticRun run = Simulate(c, *map, 60, at.back() + 1, noise, 1000 + r, length);
    auto est = KalmanOnCountEstimator::Create(
        model, estimation::CovarianceMode::kExtended,
        length_aware ? std::optional<UnitForceMap>(*map) : std::nullopt);
    EXPECT_TRUE(est.ok());
    KalmanOnCountEstimator& e = **est;
    for (int k = 0; k <= at.back(); ++k) {
      e.UpdateWithMeasurement(run.log.force[k], run.length[k]);
      for (size_t i = 0; i < at.size(); ++i) {
        if (k != at[i]) continue;
        const double err = e.EstimatedOn() - run.true_on[k];
        sum[i] += err * err / e.EstimatedOnVariance() / runs;
      }
      e.Broadcasted({run.log.p_on[k], run.log.p_off[k]});
    }
  }
  return sum;
}

TEST(LengthModel, LengthAwareFilterIsConsistentOnAMovingTendon) {
  const std::vector<double> nees_at = MeanNees(true);
  std::cout << "length-aware mean NEES: " << nees_at[0] << " " << nees_at[1] << " " << nees_at[2]
            << "\n";
  for (double nees : nees_at) {
    EXPECT_GT(nees, 0.79);
    EXPECT_LT(nees, 1.21);
  }
}

TEST(LengthModel, AFixedOutputModelIsInconsistentOnTheSameMovingTendon) {
  double worst = 0;
  const std::vector<double> nees_at = MeanNees(false);
  std::cout << "fixed-H mean NEES: " << nees_at[0] << " " << nees_at[1] << " " << nees_at[2]
            << "\n";
  for (double nees : nees_at) worst = std::max(worst, std::abs(nees - 1));
  EXPECT_GT(worst, 0.21);
}

}  // namespace file_length_model_test
}  // namespace recruit::identification
