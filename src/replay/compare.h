// How far a recorded signal is from the simulated plant (docs/replay.md, "Criterion").
//
// The plant is replayed with S seeds under the log's broadcasts: S runs X_1..X_S of a signal
// and their mean M. The recorded signal R is compared with M (RMSE, bias = mean of R - M, lag).
// Its yardstick is the plant's own spread under the same broadcasts: each run X_a against the
// mean of the other S - 1. Were the rig the simulated plant, R would be one more such run, and
// E|R - M|^2 / (1 + 1/S) = E|X_a - M_-a|^2 / (1 + 1/(S - 1)) (the means' own variance taken
// out). The signal is flagged when R's normalised RMSE exceeds the runs' mean normalised RMSE
// by the ratio band AND by z_band of their standard deviations, or when the increments
// x(k+1) - x(k) do so by step_ratio_band and z_band. Pure: numbers in, numbers out.
#pragma once

#include <string>
#include <vector>

#include "common/result.h"

namespace recruit::replay {

struct Criterion {
  double ratio_band = 4;         // normalised RMSE / the runs' mean normalised RMSE
  double step_ratio_band = 2.5;  // the same for the increments
  double z_band = 4;             // standard deviations of the runs' normalised RMSE (both)
};

struct Residual {
  double rmse = 0;  // of the difference
  double bias = 0;  // mean of the difference (the first minus the second)
  double lag = 0;   // s; > 0: the first follows the second late (see Lag)
};

struct SignalComparison {
  Residual recorded;                 // the log against the mean of the runs
  std::vector<Residual> same_plant;  // each run against the mean of the others
  double rmse_ratio = 0;             // normalised: recorded / mean over the runs
  double rmse_z = 0;                 // (recorded - mean) / sd over the runs, normalised
  double same_plant_rmse = 0;        // mean of the runs' normalised RMSE (the band's centre)
  double same_plant_rmse_sd = 0;
  double same_plant_bias_sd = 0;  // the runs' spread of bias and lag, for reading the others
  double same_plant_lag_sd = 0;
  // The same test on the increments x(k+1) - x(k): the transients after each broadcast, without
  // the slow drift of the on-count that dominates the level's spread in an open-loop replay.
  double step_rmse = 0;  // recorded, normalised
  double step_ratio = 0, step_z = 0;
  double same_plant_step_rmse = 0, same_plant_step_rmse_sd = 0;
  bool flagged = false;
};

// The shift of `a` against `b` (s, a multiple of dT refined by a parabola through the three mean
// squared differences around the best) within +-max_lag: a(t) ~ b(t - lag).
double Lag(const std::vector<double>& a, const std::vector<double>& b, double dT, double max_lag);

// `runs`: S >= 3 runs of the signal, each as long as `recorded`.
Result<SignalComparison> CompareSignal(const std::vector<double>& recorded,
                                       const std::vector<std::vector<double>>& runs, double dT,
                                       double max_lag, const Criterion& criterion);

}  // namespace recruit::replay
