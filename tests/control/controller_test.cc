// RecruitmentController with the output-only estimator, against the law computed by hand, and
// the estimator factory's validation.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "control/on_count_estimator.h"
#include "control/output_estimator.h"
#include "control/recruitment_controller.h"

namespace recruit::control {
namespace file_controller_test {

TEST(OutputOnlyEstimator, CountIsForceOverUnitForceClampedToFeasible) {
  OutputOnlyEstimator e(60, 0.5);
  e.UpdateWithMeasurement(10.0);
  EXPECT_DOUBLE_EQ(e.EstimatedOn(), 20.0);
  EXPECT_TRUE(std::isnan(e.EstimatedOnVariance()));
  EXPECT_DOUBLE_EQ(e.StateEstimate()(0), 40.0);
  EXPECT_DOUBLE_EQ(e.StateEstimate()(1), 20.0);
  e.UpdateWithMeasurement(-1.0);
  EXPECT_DOUBLE_EQ(e.EstimatedOn(), 0.0);
  e.UpdateWithMeasurement(100.0);
  EXPECT_DOUBLE_EQ(e.EstimatedOn(), 60.0);
}

TEST(RecruitmentController, StepAppliesTheLawToTheObservedCount) {
  ControllerParams p;
  p.num_units = 60;
  p.unit_force = 0.5;
  p.dT = 0.5;
  p.lambda = 0.2;
  auto c = RecruitmentController::Create(p, std::make_unique<OutputOnlyEstimator>(60, 0.5));
  ASSERT_TRUE(c.ok()) << c.error();
  // Reference 15 N = 30 units; measured 10 N = 20 units: p_on = 0.2 * 10 / 40.
  Broadcast b = c->Step(15.0, 10.0);
  EXPECT_DOUBLE_EQ(c->target_on(), 30.0);
  EXPECT_DOUBLE_EQ(c->estimated_on(), 20.0);
  EXPECT_DOUBLE_EQ(b.p_on, 0.05);
  EXPECT_EQ(b.p_off, 0);
  // Measured 20 N = 40 units: release 0.2 * 10 / 40.
  b = c->Step(15.0, 20.0);
  EXPECT_DOUBLE_EQ(b.p_off, 0.05);
  EXPECT_EQ(b.p_on, 0);
}

TEST(RecruitmentController, RejectsInvalidParameters) {
  ControllerParams p;
  p.unit_force = 0.5;
  p.lambda = 0;
  auto c = RecruitmentController::Create(p, std::make_unique<OutputOnlyEstimator>(60, 0.5));
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.error().find("lambda"), std::string::npos);
  p.lambda = 0.2;
  p.unit_force = -1;
  auto d = RecruitmentController::Create(p, std::make_unique<OutputOnlyEstimator>(60, 0.5));
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.error().find("unit_force"), std::string::npos);
}

TEST(EstimatorSpec, ParseRejectsUnknownKindsAndModes) {
  EXPECT_TRUE(EstimatorSpec::Parse("output").ok());
  auto k = EstimatorSpec::Parse("kalman3");
  ASSERT_FALSE(k.ok());
  EXPECT_NE(k.error().find("kalman-augmented"), std::string::npos);
  auto m = EstimatorSpec::Parse("kalman2", "optimistic");
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().find("conservative"), std::string::npos);
  EXPECT_FALSE(EstimatorSpec::Parse("kalman-augmented", "extended", "", 7).ok());
}

TEST(EstimatorSpec, FromJsonNamesTheFileAndField) {
  auto ok = EstimatorSpec::FromJson(
      nlohmann::json::parse(R"({"kind":"kalman2","covariance":"conservative"})"), "task.json");
  ASSERT_TRUE(ok.ok()) << ok.error();
  EXPECT_EQ(ok->kind, EstimatorKind::kKalman2);
  EXPECT_EQ(ok->covariance, estimation::CovarianceMode::kConservative);
  auto bad =
      EstimatorSpec::FromJson(nlohmann::json::parse(R"({"num_states":"many"})"), "task.json");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().find("task.json"), std::string::npos);
  EXPECT_NE(bad.error().find("num_states"), std::string::npos);
  auto unknown = EstimatorSpec::FromJson(nlohmann::json::parse(R"({"knd":"output"})"), "task.json");
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().find("knd"), std::string::npos);
}

TEST(EstimatorSpec, DefaultModelFileNamesTheSamplingPeriod) {
  EXPECT_EQ(DefaultModelFile(0.5, 20), "models/identified/bench_n60_dt0.5_m20.json");
  EXPECT_EQ(DefaultModelFile(2.0, 20), "models/identified/bench_n60_dt2.0_m20.json");
  EXPECT_EQ(DefaultModelFile(0.25, 8), "models/identified/bench_n60_dt0.25_m8.json");
}

}  // namespace file_controller_test
}  // namespace recruit::control
