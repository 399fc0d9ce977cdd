// Closed-loop metrics as pure functions of sampled signals (docs/paper-reproduction.md gives the
// definitions). Signals are sampled at times t[k]; each sample stands for [t[k], t[k+1]).
#pragma once

#include <vector>

#include "sim/reference.h"

namespace recruit::sim {

// sqrt(mean (y - r)^2).
double TrackingRmse(const std::vector<double>& r, const std::vector<double>& y);

// Integral of |y - r| dt by the rectangle rule over [t0, t_end); `t_end` closes the last sample.
double IntegralAbsoluteError(const std::vector<double>& t, const std::vector<double>& r,
                             const std::vector<double>& y, double t_end);

// Response of one step of the reference.
struct StepResponse {
  ReferenceStep step;
  double overshoot = 0;  // max excursion past the new value in the step's direction, / |to - from|
  double settling_time = 0;  // s after the step until y stays within band * |to - from| of `to`
  bool settled = false;      // within the band at the end of the hold
};

// The steps scored up to the first disturbance (a push) that starts inside their hold: what
// follows is the disturbance's response, not the step's (DisturbanceResponse).
std::vector<ReferenceStep> StepsUntilDisturbances(std::vector<ReferenceStep> steps,
                                                  const std::vector<double>& starts);

// A disturbance's window: from its start to the next disturbance or step of the reference, or
// the end of the run.
struct DisturbanceWindow {
  double start = 0, end = 0;
};
std::vector<DisturbanceWindow> DisturbanceWindows(std::vector<double> starts,
                                                  const std::vector<ReferenceStep>& steps,
                                                  double duration);

struct DisturbanceResponse {
  DisturbanceWindow window;
  double peak_deviation = 0;   // max |y - r| in the window (the tracked unit)
  double final_deviation = 0;  // |y - r| at the window's last sample
};

// Overshoot and settling time of y for each step of the reference.
std::vector<StepResponse> StepResponses(const std::vector<double>& t, const std::vector<double>& y,
                                        const std::vector<ReferenceStep>& steps, double band);

// Oscillation: excess total variation, (TV(y) - TV(r)) / TV(r). Zero for a monotone response to
// each change of the reference, grows by 2 A / TV(r) for every extra swing of amplitude A.
double ExcessTotalVariation(const std::vector<double>& r, const std::vector<double>& y);

// Unit switching rate: units switched on or off per unit and per second, from the on-count
// sampled after each step (a broadcast moves units in one direction only, so count changes are
// the transitions).
double SwitchingRate(const std::vector<int>& on_count, int num_units, double duration);

// Estimator accuracy at the control instants.
struct EstimatorScore {
  double rmse = 0;         // sqrt(mean (n^ - n)^2), units
  double mean_nees = 0;    // mean of (n^ - n)^2 / var(n^) over samples with var > 0
  double within3 = 0;      // fraction of samples with |n^ - n| <= 3
  double within_band = 0;  // fraction with |n^ - n| <= band (ScoreEstimator's; default 3)
  int samples = 0;
};
EstimatorScore ScoreEstimator(const std::vector<double>& estimated,
                              const std::vector<double>& truth, const std::vector<double>& variance,
                              double band = 3);

}  // namespace recruit::sim
