// One interface over the estimators that `recruit filter` and the comparisons run offline:
// the population Kalman filter (three covariance modes), the exact Bayesian filter and the
// particle filter. The per-step fast paths are the concrete classes; this is for offline runs.
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <string>

#include "common/result.h"
#include "estimation/filter_model.h"

namespace recruit {

class CountFilter {
 public:
  virtual ~CountFilter() = default;
  virtual void Predict(const Eigen::MatrixXd& A) = 0;  // A validated by the caller
  virtual void Update(const Eigen::VectorXd& y) = 0;
  virtual Eigen::VectorXd Mean() const = 0;        // counts per state
  virtual Eigen::MatrixXd Covariance() const = 0;  // of the counts
};

struct CountFilterOptions {
  std::string estimator = "extended";  // extended, conservative, plain, exact, particle
  int particles = 1000;                // particle
  uint64_t seed = 1;                   // particle
  uint64_t max_states = 200000;        // exact
};

// The estimator names accepted by MakeCountFilter, for help texts.
inline constexpr const char* kEstimatorNames = "extended, conservative, plain, exact, particle";

Result<std::unique_ptr<CountFilter>> MakeCountFilter(const FilterModel& model,
                                                     const CountFilterOptions& options);

}  // namespace recruit
