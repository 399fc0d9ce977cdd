// The exact Bayesian filter over every count vector: the accuracy reference for the population
// Kalman filter, and its speed peer.
//
// The belief is a probability for each of the C(N + m - 1, m - 1) count vectors X with
// sum X = N. Prediction: Pr(X' | X, A) is the distribution of the sum of m independent
// multinomials Mult(X_j, A(:, j)) (the convolution of the columns' draws); process noise G w is
// not modelled (the model's G must be empty). Update: Gaussian likelihood
// exp(-1/2 (y - H X)^T R^-1 (y - H X)). Estimates are the posterior mean and covariance.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <list>
#include <vector>

#include "common/result.h"
#include "estimation/filter_model.h"

namespace recruit::estimation {

struct ExactFilterOptions {
  uint64_t max_states = 200000;  // refuse larger count-vector spaces
  // Transition tables (S x S doubles) are cached per distinct A while they fit this budget;
  // otherwise each prediction computes rows on the fly (same result, slower).
  uint64_t cache_bytes = 256ull << 20;
};

class ExactBayesFilter {
 public:
  // Prior: a point mass at x0 when P0 = 0 (x0 must then be integer counts), otherwise the
  // Gaussian N(x0, P0) restricted to the count vectors (pseudo-inverse of P0, which has rank
  // m - 1). Errors when there are more than options.max_states count vectors, when the model
  // has process noise, or when (N + 1)^(m - 1) (the convolution grid) exceeds 2^24.
  static Result<ExactBayesFilter> Create(const FilterModel& model,
                                         const ExactFilterOptions& options = {});

  void Predict(const Eigen::MatrixXd& A);  // A validated by the caller
  void Update(const Eigen::VectorXd& y);

  Eigen::VectorXd Mean() const;
  Eigen::MatrixXd Covariance() const;
  const std::vector<double>& probabilities() const { return p_; }
  // Replaces the belief (for example by the prior of a new run, keeping the cached tables).
  // `p` has num_count_vectors() non-negative entries summing to 1.
  Status SetProbabilities(const std::vector<double>& p);
  // Count vector k (m entries).
  Eigen::VectorXd State(size_t k) const;
  size_t num_count_vectors() const { return p_.size(); }

 private:
  ExactBayesFilter() = default;
  // Pr(X' = . | X = state k, A) accumulated as weight * row into `out` (size S).
  void AccumulateRow(size_t k, const Eigen::MatrixXd& A, double weight, double* out);
  void PrepareColumnPmfs(const Eigen::MatrixXd& A);
  size_t GridIndexToState(int64_t grid_index) const { return grid_to_state_[grid_index]; }

  int m_ = 0;
  int64_t N_ = 0;
  Eigen::MatrixXd H_;
  Eigen::LLT<Eigen::MatrixXd> R_llt_;
  std::vector<int32_t> states_;         // S x m, row-major
  std::vector<int64_t> grid_index_;     // grid index of each state
  std::vector<int32_t> grid_to_state_;  // grid index -> state (or -1)
  std::vector<int64_t> radix_;          // (N + 1)^i
  std::vector<double> p_;               // belief
  std::vector<double> scratch_;
  Eigen::MatrixXd HX_;  // r x S: H X for every state
  ExactFilterOptions options_;
  // Sparse multinomial pmfs per source column j and count n: (grid offset, probability).
  std::vector<std::vector<std::vector<std::pair<int64_t, double>>>> pmf_;
  Eigen::MatrixXd pmf_A_;
  struct CachedTable {
    Eigen::MatrixXd A;
    std::vector<double> T;  // S x S, row = source state
  };
  std::list<CachedTable> cache_;
};

}  // namespace recruit::estimation
