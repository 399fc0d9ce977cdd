#include "control/output_estimator.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace recruit::control {

OutputOnlyEstimator::OutputOnlyEstimator(int num_units, double unit_force,
                                         std::optional<UnitForceMap> on_force)
    : num_units_(num_units), unit_force_(unit_force), on_force_(std::move(on_force)) {}

void OutputOnlyEstimator::Reset() { on_ = 0; }

void OutputOnlyEstimator::UpdateWithMeasurement(double measured_force, double tendon_length) {
  // Clamped to the feasible counts; a NaN force keeps the last count.
  if (measured_force != measured_force) return;
  double unit = unit_force_;
  if (on_force_ && std::isfinite(tendon_length)) {
    unit = on_force_->Force(0, tendon_length);
  }
  // A slack tendon (no on unit can pull) says nothing about the count: keep the last one.
  if (!(unit > 0)) return;
  on_ = std::clamp(measured_force / unit, 0.0, static_cast<double>(num_units_));
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
