// The closed-loop metrics of metrics.h accumulated sample by sample, so that a run's memory does
// not grow with its length: each gives exactly (bit for bit: the same sums in the same order)
// what the pure function gives on the whole signal (tests/sim/metrics_test.cc).
#pragma once

#include <vector>

#include "sim/metrics.h"

namespace recruit::sim {

// Tracking RMSE, IAE, excess total variation and step responses of y against r.
class SignalMetrics {
 public:
  SignalMetrics(std::vector<ReferenceStep> steps, double band,
                std::vector<DisturbanceWindow> disturbances = {});
  // The next sample, at time t (increasing).
  void Add(double t, double r, double y);
  double TrackingRmse() const;
  double IntegralAbsoluteError(double t_end) const;  // t_end closes the last sample
  double ExcessTotalVariation() const;
  std::vector<StepResponse> StepResponses() const;
  std::vector<DisturbanceResponse> DisturbanceResponses() const;

 private:
  struct StepState {
    ReferenceStep step;
    double dir = 0;        // +1 up, -1 down
    double tolerance = 0;  // band * |to - from|
    double peak = 0;
    bool any = false;           // a sample fell in [time, end)
    bool out_seen = false;      // some sample was out of the band
    bool last_was_out = false;  // the window's latest sample was out of the band
    double t_after_out = 0;     // time of the sample after the latest out-of-band one
  };
  // The windows (steps' and disturbances') holding t, and the stretch of time [from_, until_)
  // in which they stay the same: a sample finds its windows with two comparisons, not one test of
  // every window (the windows change a few times a run).
  void FindWindows(double t);

  std::vector<StepState> steps_;
  std::vector<DisturbanceResponse> disturbances_;  // accumulated as the samples come
  // The indices of those whose window holds from_ (indices, so that a copy is right).
  std::vector<int> open_steps_, open_disturbances_;
  double from_ = 0, until_ = 0;  // empty until the first sample
  long n_ = 0;
  double sq_ = 0, iae_ = 0, tv_r_ = 0, tv_y_ = 0;
  double prev_t_ = 0, prev_r_ = 0, prev_y_ = 0, prev_abs_ = 0;
};

// ScoreEstimator, one control instant at a time; `band` (units) is EstimatorScore's within_band.
class EstimatorScoreAccumulator {
 public:
  explicit EstimatorScoreAccumulator(double band = 3) : band_(band) {}
  void Add(double estimated, double truth, double variance);
  EstimatorScore Score() const;
  double band() const { return band_; }

 private:
  double band_ = 3;
  double se_ = 0, nees_ = 0;
  int nees_n_ = 0, within_ = 0, within_band_ = 0, samples_ = 0;
};

// SwitchingRate, from the on-count after each control instant.
class SwitchingCounter {
 public:
  void Add(int on_count);
  int last() const { return last_; }
  double Rate(int num_units, double duration) const;

 private:
  long samples_ = 0, switches_ = 0;
  int last_ = 0;
};

}  // namespace recruit::sim
