#include "sim/metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

namespace recruit::sim {

double TrackingRmse(const std::vector<double>& r, const std::vector<double>& y) {
  if (r.empty()) return 0;
  double s = 0;
  for (size_t k = 0; k < r.size(); ++k) s += (y[k] - r[k]) * (y[k] - r[k]);
  return std::sqrt(s / r.size());
}

double IntegralAbsoluteError(const std::vector<double>& t, const std::vector<double>& r,
                             const std::vector<double>& y, double t_end) {
  double s = 0;
  for (size_t k = 0; k < t.size(); ++k) {
    const double next = k + 1 < t.size() ? t[k + 1] : t_end;
    s += std::abs(y[k] - r[k]) * (next - t[k]);
  }
  return s;
}

std::vector<ReferenceStep> StepsUntilDisturbances(std::vector<ReferenceStep> steps,
                                                  const std::vector<double>& starts) {
  for (ReferenceStep& s : steps) {
    for (double d : starts) {
      if (d > s.time && d < s.end) s.end = d;
    }
  }
  return steps;
}

std::vector<DisturbanceWindow> DisturbanceWindows(std::vector<double> starts,
                                                  const std::vector<ReferenceStep>& steps,
                                                  double duration) {
  std::sort(starts.begin(), starts.end());
  std::vector<DisturbanceWindow> out;
  for (double d : starts) {
    if (!(d < duration)) continue;
    DisturbanceWindow w{d, duration};
    for (double e : starts) {
      if (e > d) w.end = std::min(w.end, e);
    }
    for (const ReferenceStep& s : steps) {
      if (s.time > d) w.end = std::min(w.end, s.time);
    }
    out.push_back(w);
  }
  return out;
}

std::vector<StepResponse> StepResponses(const std::vector<double>& t, const std::vector<double>& y,
                                        const std::vector<ReferenceStep>& steps, double band) {
  std::vector<StepResponse> out;
  for (const ReferenceStep& step : steps) {
    StepResponse resp;
    resp.step = step;
    const double size = std::abs(step.to - step.from);
    const double dir = step.to > step.from ? 1.0 : -1.0;
    const auto begin = std::lower_bound(t.begin(), t.end(), step.time) - t.begin();
    const auto end = std::lower_bound(t.begin(), t.end(), step.end) - t.begin();
    if (size == 0 || begin >= end) continue;
    double peak = 0;
    long last_out = -1;
    for (long k = begin; k < end; ++k) {
      peak = std::max(peak, dir * (y[k] - step.to));
      if (std::abs(y[k] - step.to) > band * size) last_out = k;
    }
    resp.overshoot = peak / size;
    resp.settled = last_out < end - 1;
    if (last_out < 0) {
      resp.settling_time = 0;
    } else if (!resp.settled) {
      resp.settling_time = step.end - step.time;
    } else {
      resp.settling_time = t[last_out + 1] - step.time;
    }
    out.push_back(resp);
  }
  return out;
}

double ExcessTotalVariation(const std::vector<double>& r, const std::vector<double>& y) {
  double tv_r = 0, tv_y = 0;
  for (size_t k = 1; k < r.size(); ++k) {
    tv_r += std::abs(r[k] - r[k - 1]);
    tv_y += std::abs(y[k] - y[k - 1]);
  }
  // A constant reference has no variation of its own: report the response's, in its unit.
  return (tv_y - tv_r) / (tv_r > 0 ? tv_r : 1.0);
}

double SwitchingRate(const std::vector<int>& on_count, int num_units, double duration) {
  if (on_count.size() < 2 || num_units <= 0 || duration <= 0) return 0;
  long switches = 0;
  for (size_t k = 1; k < on_count.size(); ++k) switches += std::abs(on_count[k] - on_count[k - 1]);
  return switches / (static_cast<double>(num_units) * duration);
}

EstimatorScore ScoreEstimator(const std::vector<double>& estimated,
                              const std::vector<double>& truth, const std::vector<double>& variance,
                              double band) {
  EstimatorScore s;
  double se = 0, nees = 0;
  int nees_n = 0, within = 0, within_band = 0;
  for (size_t k = 0; k < estimated.size(); ++k) {
    if (!std::isfinite(estimated[k])) continue;
    const double e = estimated[k] - truth[k];
    se += e * e;
    if (std::abs(e) <= 3) ++within;
    if (std::abs(e) <= band) ++within_band;
    if (k < variance.size() && variance[k] > 0 && std::isfinite(variance[k])) {
      nees += e * e / variance[k];
      ++nees_n;
    }
    ++s.samples;
  }
  if (s.samples > 0) {
    s.rmse = std::sqrt(se / s.samples);
    s.within3 = static_cast<double>(within) / s.samples;
    s.within_band = static_cast<double>(within_band) / s.samples;
  }
  s.mean_nees = nees_n > 0 ? nees / nees_n : std::numeric_limits<double>::quiet_NaN();
  return s;
}

}  // namespace recruit::sim
