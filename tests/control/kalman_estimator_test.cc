// The Kalman on-count estimators: the prediction and update of the two-state model against the
// binomial moments and the scalar Kalman update worked by hand, the on-count of the augmented
// model as the sum over its "on" states, and the factory's checks of the model file.
#include "control/kalman_estimator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>

#include "common/rng.h"
#include "control/on_count_estimator.h"
#include "control/recruitment_controller.h"
#include "estimation/filter_model.h"
#include "identification/model_export.h"
#include "identification/transient_chain.h"
#include "tests/common/malloc_counter.h"

namespace recruit::control {
namespace file_kalman_estimator_test {

TEST(KalmanTwoState, PredictionIsTheBinomialAndUpdateTheScalarKalmanGain) {
  const int N = 60;
  const double f = 0.5, sd = 0.4;
  auto spec = EstimatorSpec::Parse("kalman2", "extended", "", 20, sd);
  ASSERT_TRUE(spec.ok());
  auto e = MakeEstimator(*spec, N, f, 0.5);
  ASSERT_TRUE(e.ok()) << e.error();
  OnCountEstimator& est = **e;
  EXPECT_DOUBLE_EQ(est.EstimatedOn(), 0.0);
  // From all off, p_on = 0.3: on ~ Bin(60, 0.3): mean 18, variance 60 * 0.3 * 0.7 = 12.6.
  est.Broadcasted({0.3, 0.0});
  EXPECT_NEAR(est.EstimatedOn(), 18.0, 1e-9);
  EXPECT_NEAR(est.EstimatedOnVariance(), 12.6, 1e-9);
  // y = 10 N: gain on the on-count k = v f / (f^2 v + R), estimate 18 + k (10 - 0.5 * 18),
  // variance v - k f v.
  const double v = 12.6, R = sd * sd, k = v * f / (f * f * v + R);
  est.UpdateWithMeasurement(10.0);
  EXPECT_NEAR(est.EstimatedOn(), 18.0 + k * (10.0 - f * 18.0), 1e-9);
  EXPECT_NEAR(est.EstimatedOnVariance(), v - k * f * v, 1e-9);
  EXPECT_NEAR(est.StateEstimate().sum(), N, 1e-9);
  est.Reset();
  EXPECT_DOUBLE_EQ(est.EstimatedOn(), 0.0);
}

TEST(KalmanAugmented, OnCountIsTheSumOverTheHeaterOnStates) {
  auto spec = EstimatorSpec::Parse("kalman-augmented");
  ASSERT_TRUE(spec.ok());
  auto e = MakeEstimator(*spec, 60, 0.45, 0.5);  // the shipped dT = 0.5 s model
  ASSERT_TRUE(e.ok()) << e.error();
  OnCountEstimator& est = **e;
  const auto on = est.OnStates();
  ASSERT_EQ(on.size(), 20u);
  // Switch everyone on: one period later all 60 are in heat1, an "on" state whose force is
  // still about zero, and the estimate counts them as on with no uncertainty.
  est.Broadcasted({1.0, 0.0});
  EXPECT_NEAR(est.EstimatedOn(), 60.0, 1e-9);
  EXPECT_NEAR(est.EstimatedOnVariance(), 0.0, 1e-9);
  EXPECT_EQ(est.StateNames()[1], "heat1");
  EXPECT_NEAR(est.StateEstimate()[1], 60.0, 1e-9);
  // Half of them switched off again: 30 are on (whatever their force), 30 off.
  est.Broadcasted({0.0, 0.5});
  const Eigen::VectorXd x = est.StateEstimate();
  double sum_on = 0;
  for (int i = 0; i < 20; ++i) sum_on += on[i] ? x[i] : 0.0;
  EXPECT_NEAR(est.EstimatedOn(), sum_on, 1e-9);
  EXPECT_NEAR(est.EstimatedOn(), 30.0, 1e-9);
  EXPECT_NEAR(x.sum(), 60.0, 1e-9);
}

TEST(KalmanAugmented, SparseBroadcastPredictionEqualsTheDenseFilter) {
  // The estimator predicts with PredictBroadcast (sparse A); the reference is the same filter
  // driven densely (FillMatrix + Predict(A)), over a sequence of broadcasts and measurements.
  const std::string file = "models/identified/bench_n60_dt0.5_m20.json";
  auto spec = EstimatorSpec::Parse("kalman-augmented", "extended", file);
  ASSERT_TRUE(spec.ok());
  auto e = MakeEstimator(*spec, 60, 0.45, 0.5);
  ASSERT_TRUE(e.ok()) << e.error();
  const auto& est = dynamic_cast<const KalmanOnCountEstimator&>(**e);
  estimation::FilterModel model = est.model();
  auto dense =
      estimation::PopulationKalmanFilter::Create(model, estimation::CovarianceMode::kExtended);
  ASSERT_TRUE(dense.ok()) << dense.error();
  const int m = model.num_states();
  Eigen::MatrixXd A(m, m);
  Eigen::VectorXd y(1);
  Rng rng(17);
  for (int k = 0; k < 200; ++k) {
    const double p_on = rng.Uniform() < 0.3 ? 0.0 : 0.5 * rng.Uniform();
    const double p_off = rng.Uniform() < 0.3 ? 0.0 : 0.5 * rng.Uniform();
    y[0] = 30.0 * rng.Uniform();
    (*e)->UpdateWithMeasurement(y[0]);
    dense->Update(y);
    (*e)->Broadcasted({p_on, p_off});
    model.broadcast.FillMatrix(p_on, p_off, A);
    dense->Predict(A);
    // Relative 1e-12 of the scales, N units and N^2 units^2 (round-off of the two orders of
    // summation, about 1e-14 relative per step, accumulates over the run).
    ASSERT_LE((est.filter().estimate() - dense->estimate()).cwiseAbs().maxCoeff(), 1e-12 * 60) << k;
    ASSERT_LE((est.filter().covariance() - dense->covariance()).cwiseAbs().maxCoeff(), 1e-12 * 3600)
        << k;
  }
}

// A control instant with the Kalman estimators (UpdateWithMeasurement: SetOutput with the
// length-dependent H, the scalar update; the law; Broadcasted: the sparse PredictBroadcast) makes
// no heap allocation once running, with and without the tendon geometry.
TEST(KalmanAugmented, ControlStepsDoNotAllocate) {
#ifndef RECRUIT_COUNTS_MALLOC
  GTEST_SKIP() << "malloc is not replaceable here (sanitizer or not glibc)";
#else
  const long check = testing::MallocCount();
  Eigen::VectorXd heap = Eigen::VectorXd::Ones(64);  // the counter sees Eigen's heap
  EXPECT_GT(testing::MallocCount(), check);
  EXPECT_EQ(heap.sum(), 64.0);
  for (const char* kind : {"kalman2", "kalman-augmented"}) {
    for (bool geometry : {false, true}) {
      ControllerParams p;
      p.num_units = 60;
      p.unit_force = 0.45;
      p.dT = 0.5;
      p.lambda = 0.5;
      if (geometry) {
        UnitGeometry g;
        g.ref_length = 0.2;
        p.geometry = g;
      }
      auto spec = EstimatorSpec::Parse(kind, "extended");
      ASSERT_TRUE(spec.ok()) << spec.error();
      auto c = RecruitmentController::Create(p, *spec);
      ASSERT_TRUE(c.ok()) << c.error();
      long before = 0;
      for (int k = 0; k <= 100; ++k) {
        if (k == 1) before = testing::MallocCount();
        const double y = 12.0 + 0.5 * (k % 9);
        c->Step(15.0, y, 0.2 + 1e-4 * (k % 5));
      }
      EXPECT_EQ(testing::MallocCount() - before, 0) << kind << (geometry ? " with geometry" : "");
    }
  }
#endif
}

TEST(KalmanAugmented, ModelIsRescaledToTheBundlesUnits) {
  auto spec = EstimatorSpec::Parse("kalman-augmented");
  auto e = MakeEstimator(*spec, 120, 0.45, 0.5);
  ASSERT_TRUE(e.ok()) << e.error();
  (*e)->Broadcasted({0.25, 0.0});
  EXPECT_NEAR((*e)->EstimatedOn(), 30.0, 1e-9);
  EXPECT_NEAR((*e)->EstimatedOnVariance(), 120 * 0.25 * 0.75, 1e-9);
}

TEST(KalmanAugmented, FactoryRejectsAModelForAnotherPeriodOrSize) {
  auto spec = EstimatorSpec::Parse("kalman-augmented", "extended",
                                   "models/identified/bench_n60_dt2.0_m20.json");
  auto e = MakeEstimator(*spec, 60, 0.45, 0.5);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().find("dt = 2"), std::string::npos) << e.error();
  // No shipped model for dT = 1 s: the message says how to make one.
  auto d = MakeEstimator(*EstimatorSpec::Parse("kalman-augmented"), 60, 0.45, 1.0);
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.error().find("recruit identify"), std::string::npos) << d.error();
  auto s = MakeEstimator(*EstimatorSpec::Parse("kalman-augmented", "extended",
                                               "models/identified/bench_n60_dt0.5_m20.json", 12),
                         60, 0.45, 0.5);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().find("num_states"), std::string::npos) << s.error();
  auto missing = MakeEstimator(
      *EstimatorSpec::Parse("kalman-augmented", "extended", "/nonexistent/model.json"), 60, 0.45,
      0.5);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().find("/nonexistent/model.json"), std::string::npos);
}

TEST(ModelExport, FilterModelFileRoundTripsTheChain) {
  identification::TransientChain c = identification::TransientChain::Uniform(8, 0.7);
  c.heat_advance << 1.0, 0.6, 0.4;
  c.force << 0.0, 0.05, 0.2, 0.35, 0.45, 0.42, 0.3, 0.12;
  c.switch_on[5] = 2;  // cool1 -> heat2
  const estimation::FilterModel f = identification::ToFilterModel(c, 60, 0.5, 0.01);
  ASSERT_TRUE(f.Validate().ok()) << f.Validate().error();
  auto back = estimation::FilterModel::FromJsonValue(f.ToJson(), "round trip");
  ASSERT_TRUE(back.ok()) << back.error();
  for (auto [pon, poff] : {std::pair{0.0, 0.0}, {0.3, 0.6}, {1.0, 1.0}}) {
    EXPECT_LT((back->broadcast.Matrix(pon, poff) - c.Matrix(pon, poff)).norm(), 1e-12);
  }
  EXPECT_LT((back->H.transpose() - c.force).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(back->R(0, 0), 0.01);
  EXPECT_EQ(back->N, 60);
  EXPECT_DOUBLE_EQ(back->x0[0], 60.0);
}

}  // namespace file_kalman_estimator_test
}  // namespace recruit::control
