// The population Markov chain of Odhner and Asada (ACC 2010), Sec. II-IV: N independent agents,
// m states, population state X = counts per state, column-stochastic transition matrix A.
// Free functions on plain Eigen values (no state), so the filters and tests share one
// definition of each equation.
#pragma once

#include <Eigen/Dense>
#include <cstdint>

#include "common/result.h"
#include "common/rng.h"

namespace recruit::estimation {

// Default tolerance on the column sums and entries of a transition matrix.
inline constexpr double kStochasticTolerance = 1e-9;

// Checks that A is square (m x m, or `expected_m` if >= 0), finite, 0 <= A_ij <= 1 and every
// column sums to 1, all within `tol`. The error names the column and entry and the tolerance;
// `what` prefixes it (for example "model.json: transition.interior").
Status ValidateColumnStochastic(const Eigen::MatrixXd& A, double tol = kStochasticTolerance,
                                int expected_m = -1, const std::string& what = "transition matrix");

// Checks a population state: length m, finite, integer-valued, non-negative, summing to N.
Status ValidateCounts(const Eigen::VectorXd& x, int m, int64_t N,
                      const std::string& what = "population state");

// One binomial draw Bin(n, p), exact in distribution (inversion for small means, the
// standard library's rejection sampler otherwise). Expected cost O(1) in n.
int64_t SampleBinomial(int64_t n, double p, Rng& rng);

// One multinomial draw of n items over the probabilities `p` (sum 1) by sequential conditional
// binomials: c_0 ~ Bin(n, p_0), c_1 ~ Bin(n - c_0, p_1 / (1 - p_0)), ... Cost O(m), not O(n).
void SampleMultinomial(int64_t n, const double* p, int m, Rng& rng, int64_t* out);

// X(t+1) from X(t) and A(t), aggregate: one multinomial per source state j with X_j agents and
// probabilities A(:, j) (eq. 9 with z the sum of centred multinomials). Cost O(m^2), not O(N).
Eigen::VectorXd SimulateStepAggregate(const Eigen::MatrixXd& A, const Eigen::VectorXd& x, Rng& rng);

// X(t+1) agent by agent: each agent in state j moves to state i with probability A_ij (inverse
// CDF of one uniform). `states` holds every agent's state and is updated in place; returns the
// new counts. Cost O(N m). The reference the aggregate sampler is checked against.
Eigen::VectorXd SimulateStepAgents(const Eigen::MatrixXd& A, std::vector<int>& states, Rng& rng);

// Counts per state of an agent-state vector.
Eigen::VectorXd CountStates(const std::vector<int>& states, int m);

// Qz(X, A) = E[z z^T | X] = diag(A X) - A diag(X) A^T (eq. 25). PSD when X >= 0.
Eigen::MatrixXd ProcessCovarianceQz(const Eigen::MatrixXd& A, const Eigen::VectorXd& x);

// The conservative bound Qz(N 1) = N (diag(A 1) - A A^T). Qz(X) = sum_j X_j S_j with
// S_j = diag(a_j) - a_j a_j^T PSD, so Qz(N 1) - Qz(X) = sum_j (N - X_j) S_j is PSD for every X
// with 0 <= X_j <= N: it dominates Qz(X) in the PSD order over the paper's box (eq. 35).
Eigen::MatrixXd ConservativeQz(const Eigen::MatrixXd& A, double N);

// Euclidean projection of x onto the scaled simplex {n_i >= 0, sum_i n_i = N} (sort-based,
// O(m log m)). Used to keep the extended filter's Qz PSD.
Eigen::VectorXd ProjectOntoSimplex(const Eigen::VectorXd& x, double N);

// Stationary distribution pi of a column-stochastic A (A pi = pi, pi >= 0, sum 1): the null
// vector of (A - I) found by a full-pivot LU of the system with one row replaced by sum = 1.
// Errors when A is not stochastic or the chain is not ergodic enough for pi to be unique.
Result<Eigen::VectorXd> StationaryDistribution(const Eigen::MatrixXd& A);

// N (diag pi - pi pi^T): the limit of Cov[X] with no data (eq. 30).
Eigen::MatrixXd EquilibriumCovariance(const Eigen::VectorXd& pi, double N);

// The eq. 34/36 picture of the no-data covariance recursion P(t+1) = A P A^T + Q(t).
// V holds the left eigenvectors of A (right eigenvectors of A^T) as columns, sorted by
// decreasing |lambda|, lambda_1 = 1 first with e_1 = 1 (all ones). Gamma = V^T P V evolves as
// Gamma_ij(t+1) = lambda_i lambda_j Gamma_ij(t) + e_i^T Q(t) e_j (eq. 34).
// `Qmax` is a PSD upper bound of every Q(t) (for example the conservative Qz(N 1) plus
// G Qw G^T). Then |e_i^T Q(t) e_j| <= Qbar_ij = sqrt(e_i^T Qmax e_i * e_j^T Qmax e_j)
// (Cauchy-Schwarz on the PSD Q(t), and Q(t) <= Qmax), and by induction from Gamma(0) = 0
// |Gamma_ij(t)| <= bound_ij = Qbar_ij / (1 - |lambda_i lambda_j|) for every t (eq. 36), with
// bound_11 = 0 (1^T P = 0). Requires a real spectrum with |lambda_i| < 1 for i > 1 (true for
// the two-state and birth-death chains, whose A is similar to a symmetric matrix); a complex
// spectrum is an error.
struct GammaBound {
  Eigen::VectorXd lambda;  // eigenvalues of A, lambda(0) = 1
  Eigen::MatrixXd V;       // columns e_i
  Eigen::MatrixXd bound;   // m x m, the eq. 36 limit of |Gamma_ij|
  Eigen::MatrixXd Gamma(const Eigen::MatrixXd& P) const { return V.transpose() * P * V; }
};
Result<GammaBound> ComputeGammaBound(const Eigen::MatrixXd& A, const Eigen::MatrixXd& Qmax);

// Number of count vectors of N agents over m states: C(N + m - 1, m - 1), saturating at
// `cap` + 1 so huge spaces do not overflow.
uint64_t CountStateVectors(int64_t N, int m, uint64_t cap = UINT64_MAX - 1);

}  // namespace recruit::estimation
