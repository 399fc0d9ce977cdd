// ForceSensor against closed forms: the noise's mean and variance (chi-square band), the
// quantisation step and its error bound, Sheppard's variance sigma^2 + q^2 / 12 for noise plus
// quantisation, the hold between samples, reproducibility by seed, and validation messages.
#include "sim/force_sensor.h"

#include <gtest/gtest.h>

#include <cmath>

namespace recruit::sim {
namespace file_force_sensor_test {

struct Moments {
  double mean = 0, var = 0;
};

Moments ErrorMoments(ForceSensor& s, double force, int n) {
  double sum = 0, sum2 = 0;
  for (int i = 0; i < n; ++i) {
    const double e = s.SampleAndHold(force) - force;
    sum += e;
    sum2 += e * e;
  }
  Moments m;
  m.mean = sum / n;
  m.var = sum2 / n - m.mean * m.mean;
  return m;
}

TEST(ForceSensor, ExactWithoutNoiseOrResolution) {
  auto s = ForceSensor::Create({0, 0}, 1);
  ASSERT_TRUE(s.ok());
  EXPECT_TRUE(std::isnan(s->held()));
  EXPECT_EQ(s->SampleAndHold(12.345678), 12.345678);
}

TEST(ForceSensor, NoiseVarianceWithinChiSquareBand) {
  // n = 40000 samples: the sample variance / sigma^2 has sd sqrt(2 / n) = 0.0071; 4 sd band.
  const double sigma = 0.05;
  const int n = 40000;
  auto s = ForceSensor::Create({sigma, 0}, 7);
  ASSERT_TRUE(s.ok());
  const Moments m = ErrorMoments(*s, 10.0, n);
  EXPECT_NEAR(m.var / (sigma * sigma), 1.0, 4 * std::sqrt(2.0 / n));
  EXPECT_NEAR(m.mean, 0.0, 4 * sigma / std::sqrt(n));
}

TEST(ForceSensor, QuantisesToMultiplesOfTheResolution) {
  const double q = 0.02;
  auto s = ForceSensor::Create({0, q}, 3);
  ASSERT_TRUE(s.ok());
  for (double f = -1.0; f < 1.0; f += 0.00377) {
    const double y = s->SampleAndHold(f);
    EXPECT_NEAR(y / q, std::round(y / q), 1e-9) << f;
    EXPECT_LE(std::abs(y - f), q / 2 + 1e-12) << f;
  }
  EXPECT_DOUBLE_EQ(s->SampleAndHold(0.031), 0.04);  // 1.55 steps -> 2
  EXPECT_DOUBLE_EQ(s->SampleAndHold(0.029), 0.02);  // 1.45 steps -> 1
}

TEST(ForceSensor, NoisePlusQuantisationFollowsSheppard) {
  // With sigma >= q the quantisation error is nearly uniform and independent of the signal:
  // Var = sigma^2 + q^2 / 12 (Sheppard). Without the q^2/12 term the ratio would be 0.75.
  const double sigma = 0.05, q = 0.1;
  const int n = 40000;
  auto s = ForceSensor::Create({sigma, q}, 11);
  ASSERT_TRUE(s.ok());
  const Moments m = ErrorMoments(*s, 3.0137, n);
  const double expected = sigma * sigma + q * q / 12;
  EXPECT_NEAR(m.var / expected, 1.0, 0.04);
}

TEST(ForceSensor, HoldsTheReadingBetweenSamples) {
  auto s = ForceSensor::Create({0.1, 0.01}, 5);
  ASSERT_TRUE(s.ok());
  const double y = s->SampleAndHold(4.0);
  EXPECT_EQ(s->held(), y);
  EXPECT_EQ(s->held(), y);  // reading again does not draw noise
  const double y2 = s->SampleAndHold(4.0);
  EXPECT_NE(y2, y);  // a new sample draws new noise
  EXPECT_EQ(s->held(), y2);
}

TEST(ForceSensor, SameSeedSameReadingsOtherSeedOther) {
  auto a = ForceSensor::Create({0.1, 0}, 42), b = ForceSensor::Create({0.1, 0}, 42),
       c = ForceSensor::Create({0.1, 0}, 43);
  for (int i = 0; i < 10; ++i) {
    const double ya = a->SampleAndHold(1), yb = b->SampleAndHold(1), yc = c->SampleAndHold(1);
    EXPECT_EQ(ya, yb);
    EXPECT_NE(ya, yc);
  }
}

TEST(SensorParams, FromJsonValidates) {
  auto ok = SensorParams::FromJson({{"noise_std", 0.05}, {"resolution", 0.01}}, "t.json.sensor");
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(ok->noise_std, 0.05);
  EXPECT_EQ(ok->resolution, 0.01);
  auto neg = SensorParams::FromJson({{"noise_std", -1}}, "t.json.sensor");
  ASSERT_FALSE(neg.ok());
  EXPECT_NE(neg.error().find("t.json.sensor.noise_std"), std::string::npos) << neg.error();
  auto unknown = SensorParams::FromJson({{"gain", 1}}, "t.json.sensor");
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().find("allowed: noise_std, resolution"), std::string::npos);
  EXPECT_FALSE(SensorParams::FromJson(nlohmann::json::array(), "t.json.sensor").ok());
}

}  // namespace file_force_sensor_test
}  // namespace recruit::sim
