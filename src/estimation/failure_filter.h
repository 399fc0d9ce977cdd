// The population Kalman filter with absorbing failed states (docs/failures.md).
//
// The unit chain (m working states, the paper's filter) is augmented with two absorbing classes
// of m states each: "open" units (never heated again) and "stuck" units (heated for good). A
// failed unit keeps its thermal transient but ignores broadcasts, so both classes evolve by the
// chain's interior A_w(0, 0); a unit failing open from a heated state j enters the open class at
// the cooling state of its temperature (off_target[j]), one failing stuck from an unheated state
// enters the stuck class at the first heating state (on_target[j]). With a force scale c of the
// working units (functional fatigue) the state and output are
//   X = [x_w; x_open; x_stuck] (3m),  y = c H_w x_w + H_w x_open + H_w x_stuck + v.
// Over one control period a working unit in heated state j fails open with q_o, stuck with q_s
// (prior hazards), else moves by the broadcast A_w(p_on, p_off):
//   A = [[A_w D, 0, 0], [q_o F_o, A_w(0,0), 0], [q_s F_s, 0, A_w(0,0)]],
// D = diag(1 - q_o,j - q_s,j), F_o / F_s the entry maps above; A is column-stochastic, so the
// paper's Qz(X) = diag(A X) - A diag(X) A^T holds as it is.
//
// Abrupt failures (a broken lead, a burnt driver) are far likelier at once than the prior hazard
// says; a two-sided CUSUM on the normalised innovations e = (y - y^) / sqrt(S) declares one
// (force persistently below the prediction: open; above: stuck). A declaration goes back to the
// prior at the CUSUM's onset (the instant its statistic last left 0, at most kHistory instants
// back), adds there the covariance of a jump into the failed class: a common cause taking a
// fraction f of the working units in proportion to each state's count, sd_f^2 v v^T with
// v = sum_j x_j (e_fail(j) - e_j), plus the Qz of one step with independent failures of
// probability q_J; the mean is unchanged. The measurements and broadcasts since the onset are
// replayed, and place the failed units. From then on every prediction adds the Qz of
// independent failures into the declared class with probability q_S (mean unchanged), so that
// units lost while off are found when the controller fails to recruit them.
//
// Until the first declaration, with zero prior hazards and no fatigue estimate, the failed
// classes hold 0 exactly and the filter is the paper's filter (PopulationKalmanFilter) on x_w,
// run by the same code: bit-identical. From then on the augmented (3m + 1) filter runs dense.
#pragma once

#include <Eigen/Dense>
#include <deque>

#include "common/result.h"
#include "estimation/filter_model.h"
#include "estimation/population_kalman_filter.h"

namespace recruit {

// The augmented chain's A (3m x 3m, classes working, open, stuck) for a broadcast: heated working
// states fail open with q_open and stuck with q_stuck per period; failed classes absorb and
// follow the chain's interior.
Eigen::MatrixXd AugmentedTransition(const BroadcastTransitionModel& chain, double p_on,
                                    double p_off, double q_open, double q_stuck);
// The state a working unit in state j enters when it fails open / stuck (within its class).
int OpenEntry(const BroadcastTransitionModel& chain, int j);
int StuckEntry(const BroadcastTransitionModel& chain, int j);

struct FailureFilterParams {
  // Prior probabilities, per control period, that a working unit in a heated state fails open or
  // stuck (e.g. rate per hour heated x dT / 3600).
  double open_hazard = 0, stuck_hazard = 0;
  // Detection: CUSUM drift k and threshold h on the normalised innovations (two-sided).
  bool detect = true;
  double cusum_drift = 1.0;
  double cusum_threshold = 8;
  // The covariance jump at a declaration: a common cause that takes a fraction f of the working
  // units in proportion to each state's count (std of f), plus independent failures with
  // probability jump_hazard per working unit.
  double jump_fraction_std = 0.3;
  double jump_hazard = 0.005;
  // After a declaration into a class, every prediction adds the Qz of independent failures into
  // it with this probability (the mean is not moved): the count of failed units stays free to
  // follow what later broadcasts reveal (units lost while off show only when recruited).
  double settle_hazard = 0.05;
  // Random-walk variance of the working units' force scale per control period; 0 = c fixed at 1.
  double scale_variance = 0;

  Status Validate() const;
};

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
  // The augmented estimate [x_w; x_open; x_stuck] (3m) and its covariance.
  const Eigen::VectorXd& estimate() const;
  const Eigen::MatrixXd& covariance() const;
  double force_scale() const { return augmented_ ? x_[3 * m_] : 1.0; }
  double open() const { return augmented_ ? x_.segment(m_, m_).sum() : 0.0; }
  double stuck() const { return augmented_ ? x_.segment(2 * m_, m_).sum() : 0.0; }
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
  // The state a working unit in state j enters when it fails into class `to` (1 open, 2 stuck).
  int FailEntry(int j, int to) const;
  // Qz of one step with independent failures of probability q from every working state into
  // class `to` at a feasible X (3m entries).
  Eigen::MatrixXd JumpQz(const Eigen::VectorXd& xq, double q, int to) const;
  // The covariance added at a declared failure into class `to`.
  Eigen::MatrixXd JumpCovariance(int to) const;
  // The augmented output row [c H, H, H, dy/dc] for the working-state row H.
  Eigen::RowVectorXd OutputRow(const Eigen::MatrixXd& H) const;
  double Predicted(const Eigen::MatrixXd& H) const;
  void UpdateCore(double y, const Eigen::MatrixXd& H, double R);
  void PredictCore(double p_on, double p_off);

  FilterModel model_;
  CovarianceMode mode_;
  FailureFilterParams params_;
  PopulationKalmanFilter inner_;
  int m_ = 0;
  double N_ = 0;
  bool augmented_ = false;
  Eigen::VectorXd x_;  // 3m + 1: [x_w; x_open; x_stuck; c]
  Eigen::MatrixXd P_, A_;
  Eigen::MatrixXd H_, R_;  // the working states' output (1 x m), noise
  mutable Eigen::VectorXd view_x_;
  mutable Eigen::MatrixXd view_P_;
  double g_low_ = 0, g_high_ = 0;                   // CUSUM statistics
  bool declared_class_[3] = {false, false, false};  // classes declared since Reset
  int declarations_ = 0;
  bool declared_last_ = false;
  // One control instant as the filter saw it: the prior (augmented form), the measurement and
  // its output model, the broadcast that followed. A declaration replays from the onset.
  struct History {
    Eigen::VectorXd x;
    Eigen::MatrixXd P, H;
    double R = 0, y = 0, p_on = 0, p_off = 0;
  };
  static constexpr int kHistory = 40;
  std::deque<History> history_;
  int onset_low_ = 0, onset_high_ = 0;  // instants since each CUSUM statistic left 0
};

}  // namespace recruit
