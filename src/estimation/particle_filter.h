// Bootstrap particle filter over integer count vectors: each particle is a population state X
// (m non-negative integers summing to N), moved by the chain itself (one multinomial draw per
// source state, SimulateStepAggregate) and weighted by the Gaussian measurement likelihood.
// Systematic resampling when the effective sample size drops below a threshold.
// Randomness only from the Rng the caller passes to each call.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <vector>

#include "common/result.h"
#include "common/rng.h"
#include "estimation/filter_model.h"

namespace recruit::estimation {

struct ParticleFilterOptions {
  int num_particles = 1000;
  double resample_threshold = 0.5;  // resample when ESS < threshold * num_particles
};

class ParticleFilter {
 public:
  // Initial particles: all at x0 when P0 = 0 (x0 must be integer counts); otherwise draws from
  // N(x0, P0), projected onto the simplex and rounded to counts that sum to N.
  // Errors when the model has process noise (not modelled) or num_particles < 1.
  static Result<ParticleFilter> Create(const FilterModel& model,
                                       const ParticleFilterOptions& options, Rng& rng);

  void Predict(const Eigen::MatrixXd& A, Rng& rng);  // A validated by the caller
  void Update(const Eigen::VectorXd& y, Rng& rng);

  Eigen::VectorXd Mean() const;
  Eigen::MatrixXd Covariance() const;
  double EffectiveSampleSize() const;
  int num_particles() const { return static_cast<int>(weights_.size()); }
  // Particle k's counts.
  Eigen::VectorXd Particle(int k) const;

 private:
  ParticleFilter() = default;
  void Resample(Rng& rng);

  int m_ = 0;
  int64_t N_ = 0;
  Eigen::MatrixXd H_;
  Eigen::LLT<Eigen::MatrixXd> R_llt_;
  ParticleFilterOptions options_;
  std::vector<int64_t> counts_, next_;  // num_particles x m, row-major
  std::vector<double> weights_;         // normalised
  std::vector<double> logw_;
  std::vector<int64_t> draw_;
};

// Rounds a non-negative real vector summing to N to integer counts summing to N (largest
// remainders); negative entries are first projected away.
Eigen::VectorXd RoundToCounts(const Eigen::VectorXd& x, int64_t N);

}  // namespace recruit::estimation
