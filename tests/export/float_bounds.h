// What tests/export compares an exported package with the C++ controller by: the float package's
// stated bound (docs/export.md), the deviations of a replayed log against it, and the metric
// means of closed-loop runs over seeds.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace recruit::exporter::testing {

// |a - b| relative to max(|a|, |b|); 0 when both are NaN or both 0.
inline double Rel(double a, double b) {
  if (std::isnan(a) && std::isnan(b)) return 0;
  const double scale = std::max(std::abs(a), std::abs(b));
  return scale == 0 ? 0 : std::abs(a - b) / scale;
}

// The float package's bound against the C++ controller (double) over the recorded runs: the
// measured maxima with a margin (docs/export.md). The force reference is in N for the hand-set
// tasks and relative to max(1 N, reference) for the self-tuned ones (a float rounds a bundle's
// hundreds of newtons to 1e-5 N). A broadcast inherits the estimate's deviation divided by the
// units on (p_off = lambda (n^ - n_ref) / n^ when few are on: the self-tuned arm's extensor at
// 3.4 units on, 1.2e-5), hence 1e-4 = lambda 0.2 x the estimate's 2e-3 units / 4 units.
inline constexpr double kFloatBroadcast = 1e-4;  // p_on, p_off (absolute)
inline constexpr double kFloatEstimate = 2e-3;   // units
inline constexpr double kFloatVariance = 2e-4;   // relative to max(1, variance)
inline constexpr double kFloatForceRef = 2e-5;   // N, or relative to max(1 N, reference)

// Largest deviations of replayed bundle outputs (force reference, p_on, p_off, estimate,
// variance) from the recorded ones: broadcasts (absolute), estimates (units), variances
// (relative to max(1, |var|)), force references (as the caller measures them), and the largest
// of all relative to max(|a|, |b|) (the double criterion).
struct FloatDeviation {
  double broadcast = 0, estimate = 0, variance = 0, force_reference = 0, relative = 0;

  // One bundle's five outputs; the force reference is the caller's.
  void AddOutput(const double* got, const double* want) {
    broadcast = std::max({broadcast, std::abs(got[1] - want[1]), std::abs(got[2] - want[2])});
    estimate = std::max(estimate, std::abs(got[3] - want[3]));
    if (!(std::isnan(want[4]) && std::isnan(got[4]))) {
      variance = std::max(variance, std::abs(got[4] - want[4]) / std::max(1.0, std::abs(want[4])));
    }
    for (int f = 0; f < 5; ++f) relative = std::max(relative, Rel(got[f], want[f]));
  }
  // The larger of each.
  void Widen(const FloatDeviation& d) {
    broadcast = std::max(broadcast, d.broadcast);
    estimate = std::max(estimate, d.estimate);
    variance = std::max(variance, d.variance);
    force_reference = std::max(force_reference, d.force_reference);
    relative = std::max(relative, d.relative);
  }
  void ExpectWithinTheFloatBound() const {
    EXPECT_LE(broadcast, kFloatBroadcast);
    EXPECT_LE(estimate, kFloatEstimate);
    EXPECT_LE(variance, kFloatVariance);
    EXPECT_LE(force_reference, kFloatForceRef);
  }
};

// The float package driving the plant: over the seeds each metric's mean is the C++
// controller's within kClosedLoopFloat (relative; 0.02 absolute for fractions near 0).
inline constexpr double kClosedLoopFloat = 0.05;

class MetricMeans {
 public:
  explicit MetricMeans(std::vector<std::string> fields)
      : fields_(std::move(fields)), cpp_(fields_.size()), package_(fields_.size()) {}
  // One seed's run summaries' "metrics", the C++ controller's and the package's.
  void Add(const nlohmann::json& cpp, const nlohmann::json& package) {
    for (size_t f = 0; f < fields_.size(); ++f) {
      cpp_[f] += cpp[fields_[f]].get<double>();
      package_[f] += package[fields_[f]].get<double>();
    }
    identical_ += cpp["tracking_rmse"] == package["tracking_rmse"] ? 1 : 0;
    ++runs_;
  }
  int runs() const { return runs_; }
  int identical() const { return identical_; }  // runs with the same tracking RMSE
  void ExpectTheSame(const std::string& label) const {
    for (size_t f = 0; f < fields_.size(); ++f) {
      const double a = cpp_[f] / runs_, b = package_[f] / runs_;
      std::printf("  %-16s C++ %.6g  float %.6g\n", fields_[f].c_str(), a, b);
      EXPECT_LE(std::abs(b - a), std::max(kClosedLoopFloat * std::abs(a), 0.02))
          << label << " " << fields_[f];
    }
  }

 private:
  std::vector<std::string> fields_;
  std::vector<double> cpp_, package_;
  int runs_ = 0, identical_ = 0;
};

}  // namespace recruit::exporter::testing
