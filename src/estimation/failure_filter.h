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
// says; a generalised likelihood ratio test (FailureGlr, Willsky and Jones 1976) over the number
// k of units lost into a class at an onset tau within the last `glr_window` instants declares
// one. Each hypothesis (class, tau) carries the signature of one lost unit on the innovations
// through the running filter's own gains and broadcasts; the maximum-likelihood k and tau and
// the ratio follow in closed form. A declaration corrects the running estimate by k^ times the
// hypothesis's state deviation (truth minus estimate, per lost unit) and adds Var(k^) times its
// outer product and the spread of which states the units were lost from; the GLR then starts
// again. From then on every prediction adds the Qz of independent failures into the declared
// class with probability q_S (mean unchanged), when q_S > 0.
//
// Until the first declaration, with zero prior hazards and no fatigue estimate, the failed
// classes hold 0 exactly and the filter is the paper's filter (PopulationKalmanFilter) on x_w,
// run by the same code: bit-identical. From then on the augmented (3m + 1) filter runs dense.
#pragma once

#include <Eigen/Dense>
#include <vector>

#include "common/result.h"
#include "estimation/filter_model.h"
#include "estimation/population_kalman_filter.h"

namespace recruit::estimation {

// The augmented chain's A (3m x 3m, classes working, open, stuck) for a broadcast: heated working
// states fail open with q_open and stuck with q_stuck per period; failed classes absorb and
// follow the chain's interior.
Eigen::MatrixXd AugmentedTransition(const BroadcastTransitionModel& chain, double p_on,
                                    double p_off, double q_open, double q_stuck);
// The state a working unit in state j enters when it fails open / stuck (within its class).
int OpenEntry(const BroadcastTransitionModel& chain, int j);
int StuckEntry(const BroadcastTransitionModel& chain, int j);

// The generalised likelihood ratio test for an abrupt loss of k units into a failed class (1
// open, 2 stuck) at an unknown onset tau within the last `window` control instants, on the
// innovations of a Kalman filter that assumes no loss (Willsky and Jones, IEEE TAC 21(1) 1976).
// A hypothesis (class, tau) moves one unit, distributed as the working units were at tau, into
// the class: in the 3m augmented states the truth then deviates by delta(t) (delta(tau) =
// sum_j w_j (e_fail(j) - e_j), then propagated by the chain with the broadcasts sent), the
// filter's estimate by f(t) (f += K rho at each update, then the same propagation), and the
// innovations by k rho(t) with rho = h (delta - f). With d = sum rho nu / s and C = sum rho^2 / s,
//   k^ = d / C,  Var(k^) = 1 / C,  log-likelihood ratio l = d^2 / (2 C)   (k^ > 0 only).
// The filter's gains are taken as given (linear in the data), so the signatures are exact for a
// linear filter and first-order for the extended one.
class FailureGlr {
 public:
  FailureGlr(const BroadcastTransitionModel& chain, int window);
  void Clear();
  // Opens the hypotheses "units fail now" for the prior at this instant (3m, before its update).
  void Open(const Eigen::VectorXd& x_prior);
  // The update of this instant: innovation nu = y - y^, its variance s, the output row of the
  // true force on the 3m states h, the filter's gain on the 3m states K.
  void Update(double nu, double s, const Eigen::RowVectorXd& h, const Eigen::VectorXd& K);
  // The time update with the 3m transition the filter used.
  void Predict(const Eigen::MatrixXd& A);

  struct Best {
    int to = 0;                 // class (0: no hypothesis with k^ > 0)
    int age = 0;                // instants since the onset
    double count = 0;           // k^, units
    double variance = 0;        // 1 / C, units^2
    double llr = 0;             // d^2 / (2 C)
    Eigen::VectorXd deviation;  // delta - f now, per lost unit (3m)
  };
  // The hypothesis with the largest ratio among those whose count is known to within
  // `max_std` units (C >= 1 / max_std^2: a fresh onset's one innovation fits any count).
  Best Strongest(double max_std) const;
  // The hypothesis of class `to` with onset `age` instants ago (to = 0 if there is none; its
  // ratio is 0 when k^ <= 0).
  Best Hypothesis(int to, int age) const;
  // The onset of class `to` that best explains the innovations when the count k is known (a
  // census): the largest k d - k^2 C / 2 over its hypotheses (to = 0 if there is none).
  Best ForCount(int to, double k) const;

 private:
  int m_ = 0, window_ = 0, next_ = 0;
  std::vector<int> entry_[3];  // entry_[to][j]: the failed state (within 3m) of working state j
  // Column (to - 1) * window + slot: the hypotheses of each class, a ring over the onsets.
  Eigen::MatrixXd truth_, filt_;
  Eigen::VectorXd d_, C_;
  std::vector<int> age_;  // -1: slot unused
};

struct FailureFilterParams {
  // Prior probabilities, per control period, that a working unit in a heated state fails open or
  // stuck (e.g. rate per hour heated x dT / 3600).
  double open_hazard = 0, stuck_hazard = 0;
  // Detection: the GLR over onsets within the last glr_window instants declares when its largest
  // log-likelihood ratio passes glr_threshold with at least glr_min_count units lost.
  bool detect = true;
  int glr_window = 40;
  double glr_threshold = 13;
  double glr_min_count = 1;
  double glr_max_std = 2;  // units: only hypotheses whose count is known to within this
  // After a declaration into a class, every prediction adds the Qz of independent failures into
  // it with this probability (the mean is not moved).
  double settle_hazard = 0;
  // Random-walk variance of the working units' force scale per control period; 0 = c fixed at 1.
  double scale_variance = 0;
  // Variance of the force scale at Reset (c = 1), when it is estimated.
  double scale_initial_variance = 0;
  // The census (UpdateCensus): a class's residual (census count minus estimate) is a new jump
  // when it exceeds both census_min_jump units and census_jump_sigma standard deviations;
  // smaller residuals update the estimate as ordinary measurements.
  double census_min_jump = 0.5;
  double census_jump_sigma = 5;

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
  // Measurement update with the force y; runs the GLR (and a declaration).
  void Update(double y);
  // A control instant without a measurement (a lost sample): nothing is declared or suspected.
  void NoMeasurement() {
    declared_last_ = census_declared_, census_declared_ = false, suspicion_ = 0;
  }
  // Time update with the broadcast just sent.
  void PredictBroadcast(double p_on, double p_off);
  // A broadcast census (docs/failures.md section 5), before this instant's Update: `conducting`
  // counts the working plus stuck units, `stuck` the stuck ones, each with measurement variance
  // `variance` (units^2). Rows h1 = [1_w, 0, 1_s], h2 = [0, 0, 1_s] on the 3m states. A residual
  // beyond the jump thresholds first adds a loss of unknown count (prior variance
  // kCensusJumpVariance) along the failure test's best hypothesis for that count, and the spread
  // of which states the units left; then both rows update the augmented filter (Joseph form).
  // A census that finds the no-loss filter's counts exactly (no jump, not augmented) changes no
  // estimate. Either way the failure test starts again (the census accounts for every onset
  // before it). A jump counts as a declaration (declared_last() after this instant's Update).
  void UpdateCensus(double conducting, double stuck_count, double variance);
  static constexpr double kCensusJumpVariance = 1e4;  // units^2: a diffuse prior on the count
  int censuses() const { return censuses_; }

  int num_working_states() const { return m_; }
  // The augmented estimate [x_w; x_open; x_stuck] (3m) and its covariance.
  const Eigen::VectorXd& estimate() const;
  const Eigen::MatrixXd& covariance() const;
  double force_scale() const { return augmented_ ? x_[3 * m_] : 1.0; }
  double force_scale_variance() const { return augmented_ ? P_(3 * m_, 3 * m_) : 0.0; }
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
  // The GLR's largest log-likelihood ratio at the last Update (that of the strongest hypothesis,
  // declared or not; 0 after a declaration, which clears the test).
  double suspicion() const { return suspicion_; }
  // The GLR's hypothesis at the last declaration (class, onset age, count, variance, ratio).
  const FailureGlr::Best& last_declared() const { return last_declared_; }
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
  // Corrects the estimate for the strongest hypothesis of the GLR (a declaration).
  void Declare(const FailureGlr::Best& best);
  // The augmented output row [c H, H, H, dy/dc] for the working-state row H.
  Eigen::RowVectorXd OutputRow(const Eigen::MatrixXd& H) const;
  double Predicted(const Eigen::MatrixXd& H) const;
  // The force's noise variance at the present estimate: R + n R_transit + n^2 R_transit2, n the
  // units in transit (as the inner filter's), in whichever filter runs now.
  double OutputNoise() const;
  void UpdateCore(double y, const Eigen::MatrixXd& H, double R);
  // The augmented time update with the transition in A_.
  void PredictCore();
  // Joseph-form update of the augmented state with one measurement of output row h, given its
  // innovation (the reading minus its prediction) and noise variance r; returns the gain.
  Eigen::VectorXd ScalarUpdate(const Eigen::RowVectorXd& h, double innovation, double r);
  // Adds the covariance of a loss of unknown count into class `to` (residual k units, > 0: units
  // lost; < 0: fewer than declared).
  void AddCensusJump(int to, double k);

  FilterModel model_;
  CovarianceMode mode_;
  FailureFilterParams params_;
  PopulationKalmanFilter inner_;
  int m_ = 0;
  double N_ = 0;
  bool augmented_ = false;
  Eigen::VectorXd x_;  // 3m + 1: [x_w; x_open; x_stuck; c]
  Eigen::MatrixXd P_, A_;
  Eigen::MatrixXd H_, R_;    // the working states' output (1 x m), noise
  Eigen::VectorXd transit_;  // FilterModel::TransitWeights (empty: no transit noise)
  mutable Eigen::VectorXd view_x_;
  mutable Eigen::MatrixXd view_P_;
  FailureGlr glr_;
  Eigen::VectorXd last_gain_;                       // K of the last augmented update (3m + 1)
  bool declared_class_[3] = {false, false, false};  // classes declared since Reset
  int declarations_ = 0;
  bool declared_last_ = false;
  bool census_declared_ = false;  // the census of this instant found a jump
  int censuses_ = 0;
  double suspicion_ = 0;
  FailureGlr::Best last_declared_;
};

}  // namespace recruit::estimation
