// Identification of the augmented transient model (TransientChain) from a switching log, by
// least squares on the predicted mean force (docs/identification.md):
//   x_0 = N e_cold,  x_{k+1} = A(p_on_k, p_off_k; a) x_k,   y^_k = H x_k
//   min over a in [a_min, 1]^{2K}, H of
//       sum_{k in train} (y_k - H x_k(a))^2 + mu |D H|^2 + nu sum_i (1 - a_i)^2
// H enters linearly, so for each a it is the regularised linear least-squares solution
// (variable projection); a is fitted by a bounded Levenberg-Marquardt on the projected residual,
// alternating with a greedy least-squares choice of the mid-transient switching targets.
// D takes differences between neighbouring states along each chain (heat1.., hot) and
// (cool1.., cold), so states the data barely separate get a force between their neighbours.
// With FitOptions::monotone, H is the exact minimiser under the transient's order (force never
// falls along cold, heat1.., hot nor rises along hot, cool1.., cold): a sign-constrained
// quadratic programme (nonnegative_qp.h).
#pragma once

#include <vector>

#include "common/result.h"
#include "identification/switching_log.h"
#include "identification/transient_chain.h"

namespace recruit::identification {

struct FitOptions {
  int num_states = 20;            // m (even, >= 4)
  double holdout_fraction = 0.3;  // the last part of the log, not used to fit
  double smoothness = 1e-3;       // mu, relative to trace(X^T X) / m
  // Weight of the prior sum (1 - a_i)^2, relative to the mean square force: keeps the advance
  // probabilities the data do not constrain at 1.
  double advance_prior = 1e-4;
  double min_advance = 0.02;  // lower bound on every advance probability
  int max_iterations = 200;   // Levenberg-Marquardt iterations per round
  int max_rounds = 4;         // rounds of (advance probabilities, switching targets)
  // R is fitted by maximum likelihood under the population Kalman filter, searched in
  // [noise_floor * (settled unit force)^2, variance of the force].
  double noise_floor = 1e-4;
  // Keep the transient's order in H (OrderViolation 0): a unit heating pulls no less the longer
  // it has been on, a unit cooling no more. Without it, states the data leave loose can take
  // forces no wire has (zero mid-heating, full force one state after the switch).
  bool monotone = true;
  // Fit R (force_noise_var and the noise model; most of a small log's identification time).
  // false leaves them 0: for callers that use only the chain and H.
  bool fit_noise = true;
};

struct FitMetrics {
  int samples = 0;
  double rmse = 0;  // N, of the predicted mean force
  double r2 = 0;    // 1 - SS_res / SS_tot
};

// The measurement noise model R(x) = r0 + r_transit n + r_transit2 n^2, n = TransitCount(x) the
// sum of w_j max(0, x_j), w = TransitWeights (the states a unit leaves unswitched, by force step),
// x the filter's predicted counts. r_transit: errors independent from unit to unit; r_transit2: an
// error the units in transit share (docs/identification.md, "Noise in transit").
struct NoiseModel {
  double r0 = 0;          // N^2
  double r_transit = 0;   // N^2 per unit in transit
  double r_transit2 = 0;  // N^2 per squared count of units in transit
  double At(double n) const { return r0 + (r_transit * n + r_transit2 * (n * n)); }
};

struct IdentificationResult {
  TransientChain chain;
  double force_noise_var = 0;  // R, N^2: what the population's own spread does not explain
  // R as a function of the units in transit (MaxLikelihoodNoiseModel), on the same samples.
  NoiseModel noise;
  FitMetrics train, holdout;
  // The two-state model (H = [h_off, h_on] fitted the same way) on the same held-out data.
  FitMetrics two_state_holdout;
  double cost = 0;     // final training cost
  int iterations = 0;  // Levenberg-Marquardt iterations, all rounds
};

Result<IdentificationResult> IdentifyTransientModel(const SwitchingLog& log,
                                                    const FitOptions& options);

// Predicted mean force y^_k = H x_k for every sample of the log, from rest.
Eigen::VectorXd PredictMeanForce(const TransientChain& chain, const SwitchingLog& log);

// The measurement variance R maximising the likelihood of log.force[0, rows) under the
// population Kalman filter on `chain` (extended covariance), searched in [lo, hi] N^2.
double MaxLikelihoodNoise(const TransientChain& chain, const SwitchingLog& log, int rows, double lo,
                          double hi);

// For the chain's states a unit leaves without being switched (interior(j, j) < 1: the heating
// and cooling states), the force step to the next state over the force range; 0 for cold and
// hot (estimation::TransitWeights; FilterModel::TransitWeights of its export).
Eigen::VectorXd TransitWeights(const TransientChain& chain);

// Negative log-likelihood (up to constants, sum of log S_k + nu_k^2 / S_k) of
// log.force[0, rows) under the population Kalman filter on `chain` (extended covariance) with
// R(x^-) = noise.At(TransitCount(x^-)).
double NoiseNegLogLikelihood(const TransientChain& chain, const SwitchingLog& log, int rows,
                             const NoiseModel& noise);

// The (r0, r_transit) maximising that likelihood: Nelder-Mead on (log r0, log r_transit) from a
// start that splits the constant ML R (`constant`) between the two terms, r0 in [lo, hi]; the
// constant model (constant, 0) when the fit does not beat it.
NoiseModel MaxLikelihoodNoiseModel(const TransientChain& chain, const SwitchingLog& log, int rows,
                                   double constant, double lo, double hi);

// The samples of log[0, rows) at which the chain's mean counts hold less than half a unit in
// states whose force is neither the cold nor the hot state's (within 1 % of a settled unit's
// force): every unit's force is a settled one, so only the sensor and the settled forces' error
// are left in the residual.
std::vector<int> ForceSettledSamples(const TransientChain& chain, const SwitchingLog& log,
                                     int rows);

// R(x) for a log with realized switching fractions (the bench's): r0 the square of a robust
// scale (1.4826 MAD) of the mean prediction's residual over the force-settled samples (at least
// `lo`), r_transit2 by maximum likelihood with r0 fixed (golden section on log r_transit2;
// r_transit 0: the transit's error is shared by the units that switch together). A joint likelihood
// over (r0, r_transit) puts the transit's error into r0 when units are almost always in transit (a
// random excitation), and the filter then doubts its holds. Falls back to MaxLikelihoodNoiseModel
// without realized fractions (the residual would hold the broadcasts' binomial spread) or with
// fewer than 20 settled samples.
NoiseModel SettledNoiseModel(const TransientChain& chain, const SwitchingLog& log, int rows,
                             double constant, double lo, double hi);

// R by maximum likelihood of log.force[0, rows) under the population Kalman filter on `chain`
// (MaxLikelihoodNoise), searched in [opt.noise_floor * (settled unit force)^2, the force's
// variance]: the measurement variance (sensor noise and per-unit model error) that the
// population's own spread, which the filter carries in P, does not explain.
double ConstantNoise(const TransientChain& chain, const SwitchingLog& log, int rows,
                     const FitOptions& opt);
// R growing with the units in transit (SettledNoiseModel) in the same range, `constant` the
// ConstantNoise: what IdentifyTransientModel reports, and what a limb's identification fits
// again once its forces are final.
NoiseModel FitNoiseModel(const TransientChain& chain, const SwitchingLog& log, int rows,
                         double constant, const FitOptions& opt);

// The largest step of `chain.force` against the transient's order, N: max over the heating path
// (cold, heat1.., hot) of a fall and over the cooling path (hot, cool1.., cold) of a rise.
double OrderViolation(const TransientChain& chain);

// RMSE and R^2 of `predicted` against log.force over samples [begin, end).
FitMetrics Score(const Eigen::VectorXd& predicted, const SwitchingLog& log, int begin, int end);

}  // namespace recruit::identification
