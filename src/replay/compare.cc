#include "replay/compare.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace recruit::replay {
namespace {

// Mean of (a[k] - b[k - s])^2 over the overlap.
double ShiftedMse(const std::vector<double>& a, const std::vector<double>& b, int s) {
  const int n = static_cast<int>(a.size());
  double sum = 0;
  int count = 0;
  for (int k = std::max(0, s); k < std::min(n, n + s); ++k) {
    const double d = a[k] - b[k - s];
    sum += d * d;
    ++count;
  }
  return count > 0 ? sum / count : std::numeric_limits<double>::infinity();
}

Residual Compare(const std::vector<double>& a, const std::vector<double>& b, double dT,
                 double max_lag) {
  const size_t n = a.size();
  double sq = 0, sum = 0;
  for (size_t k = 0; k < n; ++k) {
    sq += (a[k] - b[k]) * (a[k] - b[k]);
    sum += a[k] - b[k];
  }
  return {std::sqrt(sq / n), sum / n, Lag(a, b, dT, max_lag)};
}

std::vector<double> Increments(const std::vector<double>& x) {
  std::vector<double> d;
  for (size_t k = 1; k < x.size(); ++k) d.push_back(x[k] - x[k - 1]);
  return d;
}

double Rmse(const std::vector<double>& a, const std::vector<double>& b) {
  double sq = 0;
  for (size_t k = 0; k < a.size(); ++k) sq += (a[k] - b[k]) * (a[k] - b[k]);
  return a.empty() ? 0 : std::sqrt(sq / a.size());
}

void MeanSd(const std::vector<double>& v, double* mean, double* sd) {
  double m = 0;
  for (double x : v) m += x / v.size();
  double ss = 0;
  for (double x : v) ss += (x - m) * (x - m);
  *mean = m;
  *sd = v.size() > 1 ? std::sqrt(ss / (v.size() - 1)) : 0;
}

// x / mean and (x - mean) / sd; a zero spread (a deterministic plant) makes any excess infinite.
double Ratio(double x, double mean) {
  return mean > 0 ? x / mean : (x > 0 ? std::numeric_limits<double>::infinity() : 1);
}
double Z(double x, double mean, double sd) {
  return sd > 0 ? (x - mean) / sd : (x > mean ? std::numeric_limits<double>::infinity() : 0);
}

}  // namespace

double Lag(const std::vector<double>& a, const std::vector<double>& b, double dT, double max_lag) {
  const int n = static_cast<int>(a.size());
  // At least half the samples overlap.
  const int L = std::max(0, std::min(static_cast<int>(std::floor(max_lag / dT + 1e-9)), n / 2));
  int best = 0;
  double best_mse = ShiftedMse(a, b, 0);
  for (int s = -L; s <= L; ++s) {
    const double mse = ShiftedMse(a, b, s);
    if (mse < best_mse) best_mse = mse, best = s;
  }
  double frac = 0;
  if (best > -L && best < L) {
    const double lo = ShiftedMse(a, b, best - 1), hi = ShiftedMse(a, b, best + 1);
    const double curvature = lo - 2 * best_mse + hi;
    if (curvature > 0) frac = 0.5 * (lo - hi) / curvature;  // in (-0.5, 0.5)
  }
  return (best + frac) * dT;
}

Result<SignalComparison> CompareSignal(const std::vector<double>& recorded,
                                       const std::vector<std::vector<double>>& runs, double dT,
                                       double max_lag, const Criterion& criterion) {
  const int S = static_cast<int>(runs.size());
  if (S < 3)
    return Error{"the comparison needs at least 3 simulated runs, got " + std::to_string(S)};
  const size_t n = recorded.size();
  for (const auto& r : runs) {
    if (r.size() != n) return Error{"a simulated run's length differs from the log's"};
  }
  std::vector<double> mean(n, 0.0), others(n);
  for (const auto& r : runs) {
    for (size_t k = 0; k < n; ++k) mean[k] += r[k] / S;
  }
  SignalComparison c;
  c.recorded = Compare(recorded, mean, dT, max_lag);
  std::vector<double> rmse, bias, lag, step;
  const std::vector<double> mean_steps = Increments(mean);
  for (const auto& r : runs) {
    for (size_t k = 0; k < n; ++k) others[k] = (S * mean[k] - r[k]) / (S - 1);
    step.push_back(Rmse(Increments(r), Increments(others)) / std::sqrt(1.0 + 1.0 / (S - 1)));
    c.same_plant.push_back(Compare(r, others, dT, max_lag));
    rmse.push_back(c.same_plant.back().rmse / std::sqrt(1.0 + 1.0 / (S - 1)));
    bias.push_back(c.same_plant.back().bias);
    lag.push_back(c.same_plant.back().lag);
  }
  double unused;
  MeanSd(rmse, &c.same_plant_rmse, &c.same_plant_rmse_sd);
  MeanSd(bias, &unused, &c.same_plant_bias_sd);
  MeanSd(lag, &unused, &c.same_plant_lag_sd);
  MeanSd(step, &c.same_plant_step_rmse, &c.same_plant_step_rmse_sd);
  c.step_rmse = Rmse(Increments(recorded), mean_steps) / std::sqrt(1.0 + 1.0 / S);
  c.step_ratio = Ratio(c.step_rmse, c.same_plant_step_rmse);
  c.step_z = Z(c.step_rmse, c.same_plant_step_rmse, c.same_plant_step_rmse_sd);
  const double rec = c.recorded.rmse / std::sqrt(1.0 + 1.0 / S);
  c.rmse_ratio = Ratio(rec, c.same_plant_rmse);
  c.rmse_z = Z(rec, c.same_plant_rmse, c.same_plant_rmse_sd);
  c.flagged = (c.rmse_ratio > criterion.ratio_band && c.rmse_z > criterion.z_band) ||
              (c.step_ratio > criterion.step_ratio_band && c.step_z > criterion.z_band);
  return c;
}

}  // namespace recruit::replay
