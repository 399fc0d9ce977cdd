// From a sweep's cells to what a lab acts on: per plant point, estimator and lambda, the
// recommended dT (the shortest tried that meets the tracking criterion) with its margin and the
// confidence over seeds; the critical dT where the margin crosses zero (interpolated in log dT
// between the last failing and the first passing dT); and the sensitivities of the critical dT
// to each plant axis (a least-squares fit of log dT* on the axes: elasticities).
#pragma once

#include <string>
#include <vector>

#include "sweep/grid.h"
#include "sweep/table.h"

namespace recruit::sweep {

struct Recommendation {
  int plant = 0;
  std::vector<std::pair<std::string, double>> plant_values;
  std::string estimator;
  double lambda = 0;
  bool found = false;    // some dT tried meets the criterion
  double dT = 0;         // recommended: the shortest dT tried that meets it
  double margin = 0;     // its cell margin
  double margin_se = 0;  // standard error of the per-seed margins
  // P(margin >= 0) ~ Phi(margin / margin_se); 1 or 0 when se = 0; NaN with one seed.
  double confidence = 0;
  int seeds_meeting = 0, seeds = 0;
  double critical_dT = 0;  // where the margin crosses 0 (NaN when not found)
  bool censored = false;   // the shortest dT tried already meets: critical_dT <= dT
};

std::vector<Recommendation> Recommend(const std::vector<sweep::CellStats>& cells);

struct Sensitivity {
  std::string estimator;
  double lambda = 0;
  std::string axis;
  bool log_axis = false;  // fit on ln(x) (all values > 0): slope = elasticity d ln dT* / d ln x
  double slope = 0;       // d ln dT* / d ln x, or d ln dT* / dx
  double effect = 1;      // factor on dT* over the swept range: exp(|slope| * span)
  int points = 0;         // plant points in the fit (those with an uncensored critical dT)
  bool fitted = false;    // false: too few points or the axis does not vary
};

// Per estimator and lambda, one row per plant axis, sorted by effect (largest first).
std::vector<Sensitivity> Sensitivities(const std::vector<Recommendation>& recs);

}  // namespace recruit::sweep
