#include "control/output_estimator.h"

#include <algorithm>
#include <limits>

namespace recruit::control {

OutputOnlyEstimator::OutputOnlyEstimator(int num_units, double unit_force)
    : num_units_(num_units), unit_force_(unit_force) {}

void OutputOnlyEstimator::Reset() { on_ = 0; }

void OutputOnlyEstimator::Observe(double measured_force) {
  // Clamped to the feasible counts; a NaN force keeps the last count.
  if (measured_force == measured_force) {
    on_ = std::clamp(measured_force / unit_force_, 0.0, static_cast<double>(num_units_));
  }
}

double OutputOnlyEstimator::EstimatedOnVariance() const {
  return std::numeric_limits<double>::quiet_NaN();
}

Eigen::VectorXd OutputOnlyEstimator::StateEstimate() const {
  Eigen::VectorXd x(2);
  x << num_units_ - on_, on_;
  return x;
}

}  // namespace recruit::control
