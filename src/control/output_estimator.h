// The output-only on-count: force / settled force of one unit. It is exact at steady state and
// wrong during transients: a unit that has just turned on shows a fraction of its settled force,
// so at short dT the controller over-recruits (the paper's Fig. 5 failure). With an on-force map
// (a single state, the settled on unit) the settled force is taken at the measured length.
#pragma once

#include <optional>

#include "control/on_count_estimator.h"

namespace recruit::control {

class OutputOnlyEstimator final : public OnCountEstimator {
 public:
  OutputOnlyEstimator(int num_units, double unit_force,
                      std::optional<UnitForceMap> on_force = std::nullopt);
  void Reset() override;
  using OnCountEstimator::UpdateWithMeasurement;
  void UpdateWithMeasurement(double measured_force, double tendon_length) override;
  void Broadcasted(const Broadcast& b) override {}
  double EstimatedOn() const override { return on_; }
  double EstimatedOnVariance() const override;
  Eigen::VectorXd StateEstimate() const override;  // {off, on}
  std::vector<std::string> StateNames() const override { return {"off", "on"}; }
  std::vector<bool> OnStates() const override { return {false, true}; }

 private:
  int num_units_;
  double unit_force_;
  std::optional<UnitForceMap> on_force_;
  double on_ = 0;
};

}  // namespace recruit::control
