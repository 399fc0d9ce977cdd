// One interface over the estimators that `recruit filter` and the comparisons run offline:
// the population Kalman filter (three covariance modes), the exact Bayesian filter and the
// particle filter. The per-step fast paths are the concrete classes; this is for offline runs.
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <string>

#include "common/result.h"
#include "estimation/filter_model.h"

namespace recruit::estimation {

class CountFilter {
 public:
  virtual ~CountFilter() = default;
  virtual void Predict(const Eigen::MatrixXd& A) = 0;  // A validated by the caller
  virtual void Update(const Eigen::VectorXd& y) = 0;
  virtual Eigen::VectorXd Mean() const = 0;        // counts per state
  virtual Eigen::MatrixXd Covariance() const = 0;  // of the counts
  // Predict with A(p_on, p_off) of `b` (the model's broadcast transition; inputs validated by
  // the caller). The Kalman filter uses its sparse, allocation-free path; the default builds
  // the dense matrix.
  virtual void PredictBroadcast(const BroadcastTransitionModel& b, double p_on, double p_off) {
    Predict(b.Matrix(p_on, p_off));
  }
  // Mean and the diagonal of the covariance into vectors of m entries (the Kalman filter
  // copies them without allocating).
  virtual void MeanAndVariance(Eigen::VectorXd& mean, Eigen::VectorXd& var) const {
    mean = Mean();
    var = Covariance().diagonal();
  }
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

}  // namespace recruit::estimation
