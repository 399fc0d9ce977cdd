#include "sim/metrics_stream.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

namespace recruit::sim {

SignalMetrics::SignalMetrics(std::vector<ReferenceStep> steps, double band,
                             std::vector<DisturbanceWindow> disturbances) {
  for (const ReferenceStep& s : steps) {
    const double size = std::abs(s.to - s.from);
    steps_.push_back({s, s.to > s.from ? 1.0 : -1.0, band * size});
  }
  for (const DisturbanceWindow& w : disturbances) disturbances_.push_back({w});
  // Room for every window: FindWindows never allocates.
  open_steps_.reserve(steps_.size());
  open_disturbances_.reserve(disturbances_.size());
}

void SignalMetrics::FindWindows(double t) {
  from_ = t;
  until_ = std::numeric_limits<double>::infinity();
  // Open at t: !(t < start || t >= end), as a window held a sample before. For later times the
  // set stays until a window ahead opens or an open one closes. (A NaN t is in every window, and
  // as from_ it keeps nothing: the next sample finds its windows afresh.)
  auto open = [&](double start, double end) {
    if (t < start) {
      until_ = std::min(until_, start);
    } else if (t < end) {
      until_ = std::min(until_, end);
    }
    return !(t < start || t >= end);
  };
  open_steps_.clear();
  for (size_t k = 0; k < steps_.size(); ++k) {
    if (open(steps_[k].step.time, steps_[k].step.end)) open_steps_.push_back(static_cast<int>(k));
  }
  open_disturbances_.clear();
  for (size_t k = 0; k < disturbances_.size(); ++k) {
    const DisturbanceWindow& w = disturbances_[k].window;
    if (open(w.start, w.end)) open_disturbances_.push_back(static_cast<int>(k));
  }
}

void SignalMetrics::Add(double t, double r, double y) {
  if (n_ > 0) {
    iae_ += prev_abs_ * (t - prev_t_);  // the previous sample's rectangle, now that it is closed
    tv_r_ += std::abs(r - prev_r_);
    tv_y_ += std::abs(y - prev_y_);
  }
  sq_ += (y - r) * (y - r);
  ++n_;
  prev_t_ = t, prev_r_ = r, prev_y_ = y, prev_abs_ = std::abs(y - r);
  if (!(t >= from_ && t < until_)) FindWindows(t);
  for (int k : open_steps_) {
    StepState& s = steps_[k];
    s.peak = std::max(s.peak, s.dir * (y - s.step.to));
    if (s.last_was_out) s.t_after_out = t;
    s.last_was_out = std::abs(y - s.step.to) > s.tolerance;
    s.out_seen = s.out_seen || s.last_was_out;
    s.any = true;
  }
  for (int k : open_disturbances_) {
    DisturbanceResponse& d = disturbances_[k];
    d.peak_deviation = std::max(d.peak_deviation, std::abs(y - r));
    d.final_deviation = std::abs(y - r);
  }
}

double SignalMetrics::TrackingRmse() const { return n_ > 0 ? std::sqrt(sq_ / n_) : 0.0; }

double SignalMetrics::IntegralAbsoluteError(double t_end) const {
  return n_ > 0 ? iae_ + prev_abs_ * (t_end - prev_t_) : 0.0;
}

double SignalMetrics::ExcessTotalVariation() const {
  return (tv_y_ - tv_r_) / (tv_r_ > 0 ? tv_r_ : 1.0);
}

std::vector<StepResponse> SignalMetrics::StepResponses() const {
  std::vector<StepResponse> out;
  for (const StepState& s : steps_) {
    const double size = std::abs(s.step.to - s.step.from);
    if (size == 0 || !s.any) continue;
    StepResponse resp;
    resp.step = s.step;
    resp.overshoot = s.peak / size;
    resp.settled = !s.last_was_out;
    if (!s.out_seen) {
      resp.settling_time = 0;
    } else if (!resp.settled) {
      resp.settling_time = s.step.end - s.step.time;
    } else {
      resp.settling_time = s.t_after_out - s.step.time;
    }
    out.push_back(resp);
  }
  return out;
}

std::vector<DisturbanceResponse> SignalMetrics::DisturbanceResponses() const {
  return disturbances_;
}

void EstimatorScoreAccumulator::Add(double estimated, double truth, double variance) {
  if (!std::isfinite(estimated)) return;
  const double e = estimated - truth;
  se_ += e * e;
  if (std::abs(e) <= 3) ++within_;
  if (std::abs(e) <= band_) ++within_band_;
  if (variance > 0 && std::isfinite(variance)) {
    nees_ += e * e / variance;
    ++nees_n_;
  }
  ++samples_;
}

EstimatorScore EstimatorScoreAccumulator::Score() const {
  EstimatorScore s;
  s.samples = samples_;
  if (samples_ > 0) {
    s.rmse = std::sqrt(se_ / samples_);
    s.within3 = static_cast<double>(within_) / samples_;
    s.within_band = static_cast<double>(within_band_) / samples_;
  }
  s.mean_nees = nees_n_ > 0 ? nees_ / nees_n_ : std::numeric_limits<double>::quiet_NaN();
  return s;
}

void SwitchingCounter::Add(int on_count) {
  if (samples_ > 0) switches_ += std::abs(on_count - last_);
  last_ = on_count;
  ++samples_;
}

double SwitchingCounter::Rate(int num_units, double duration) const {
  if (samples_ < 2 || num_units <= 0 || duration <= 0) return 0;
  return switches_ / (static_cast<double>(num_units) * duration);
}

}  // namespace recruit::sim
