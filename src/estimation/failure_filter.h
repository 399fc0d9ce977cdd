// The population Kalman filter with absorbing failed states (docs/failures.md).
//
// The unit chain (m working states, the paper's filter) is augmented with two absorbing states,
// "open" (never heats: the force of a cold off unit) and "stuck" (always heated: the force of a
// settled on unit), and a force scale c of the working units (functional fatigue):
//   X = [x_w (m); n_open; n_stuck],  y = c H_w x_w + h_cold n_open + h_hot n_stuck + v.
// Over one control period a working unit in state j fails open with q_o,j, stuck with q_s,j
// (prior hazards, heated states only), else moves by the broadcast A_w:
//   A = [[A_w D, 0, 0], [q_o^T, 1, 0], [q_s^T, 0, 1]],  D = diag(1 - q_o,j - q_s,j),
// column-stochastic, so the paper's Qz(X) = diag(A X) - A diag(X) A^T holds as it is.
//
// Abrupt failures (a broken lead, a burnt driver) are far likelier at once than the prior hazard
// says; a two-sided CUSUM on the normalised innovations e = (y - y^) / sqrt(S) declares one
// (force persistently below the prediction: open; above: stuck). A declaration adds, before the
// update at that instant, the Qz of one step of the absorbing chain with the jump hazard q_J
// (into open, or stuck) to the predicted covariance; the mean is unchanged and the measurements
// then place the failed units.
//
// Until the first declaration, with zero prior hazards and no fatigue estimate, the failed
// states hold 0 exactly and the filter is the paper's filter (PopulationKalmanFilter) on x_w,
// run by the same code: bit-identical. From then on the augmented (m + 2) filter runs dense.
#pragma once

#include <Eigen/Dense>

#include "common/result.h"
#include "estimation/filter_model.h"
#include "estimation/population_kalman_filter.h"

namespace recruit {

struct FailureFilterParams {
  // Prior probabilities, per control period, that a working unit in a heated state fails open or
  // stuck (e.g. rate per hour heated x dT / 3600).
  double open_hazard = 0, stuck_hazard = 0;
  // Detection: CUSUM drift k and threshold h on the normalised innovations (two-sided).
  bool detect = true;
  double cusum_drift = 1.0;
  double cusum_threshold = 8;
  // Hazard of the covariance jump at a declaration (per working unit).
  double jump_hazard = 0.2;
  // Random-walk variance of the working units' force scale per control period; 0 = c fixed at 1.
  double scale_variance = 0;

  Status Validate() const;
};

// The augmented chain's A ((m + 2) x (m + 2)) for a broadcast: heated working states fail open
// with q_open and stuck with q_stuck per period, the failed states absorb.
Eigen::MatrixXd AugmentedTransition(const BroadcastTransitionModel& chain, double p_on,
                                    double p_off, double q_open, double q_stuck);

class FailureKalmanFilter {
 public:
  // `model`: a single-output broadcast model (the working units' chain).
  static Result<FailureKalmanFilter> Create(const FilterModel& model, CovarianceMode mode,
                                            const FailureFilterParams& params);

  void Reset();
  // The working states' output row (1 x m) and R for the next Update.
  void SetOutput(const Eigen::MatrixXd& H, const Eigen::MatrixXd& R);
  // Measurement update with the force y; runs the CUSUM (and a declaration).
  void Update(double y);
  // Time update with the broadcast just sent.
  void PredictBroadcast(double p_on, double p_off);

  int num_working_states() const { return m_; }
  // The augmented estimate [x_w; open; stuck] (m + 2) and its covariance, and the fatigue scale.
  const Eigen::VectorXd& estimate() const;
  const Eigen::MatrixXd& covariance() const;
  double force_scale() const { return augmented_ ? x_[m_ + 2] : 1.0; }
  double open() const { return estimate()[m_]; }
  double stuck() const { return estimate()[m_ + 1]; }
  double working() const { return N_ - open() - stuck(); }
  // Var(working) = Var(open + stuck).
  double working_variance() const;
  // True once the augmented filter runs (a declaration, prior hazards or a fatigue estimate).
  bool augmented() const { return augmented_; }
  // Failures declared since Reset, and whether the last Update declared one.
  int declarations() const { return declarations_; }
  bool declared_last() const { return declared_last_; }
  // The paper's filter that runs until the augmented one takes over.
  const PopulationKalmanFilter& working_filter() const { return inner_; }

 private:
  FailureKalmanFilter(FilterModel model, CovarianceMode mode, FailureFilterParams params,
                      PopulationKalmanFilter inner);
  // Copies the working filter's belief into the augmented state.
  void Augment();
  // The augmented A for a broadcast ((m + 3) x (m + 3) with the scale row: identity there).
  void FillAugmentedA(double p_on, double p_off);
  // Qz of one step of the absorbing chain with hazard q from every working state into state
  // `to` (m: open, m + 1: stuck) at X.
  Eigen::MatrixXd JumpQz(const Eigen::VectorXd& x, double q, int to) const;

  FilterModel model_;
  CovarianceMode mode_;
  FailureFilterParams params_;
  PopulationKalmanFilter inner_;
  int m_ = 0;
  double N_ = 0;
  int cold_ = 0, hot_ = 0;  // working states whose force an open / stuck unit has
  bool augmented_ = false;
  Eigen::VectorXd x_;  // m + 3: [x_w; open; stuck; c]
  Eigen::MatrixXd P_, A_;
  Eigen::MatrixXd H_, R_;  // the working states' output (1 x m), noise
  mutable Eigen::VectorXd view_x_;
  mutable Eigen::MatrixXd view_P_;
  double g_low_ = 0, g_high_ = 0;  // CUSUM statistics
  int declarations_ = 0;
  bool declared_last_ = false;
};

}  // namespace recruit
