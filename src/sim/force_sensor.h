// ForceSensor: the load cell between a tendon and the controller. Every sampling period it
// samples the true tendon force, adds zero-mean Gaussian noise from its own seeded stream,
// quantises to the converter's resolution, and holds that reading until the next sample
// (sample-and-hold at dT). MuJoCo-free: the run loop hands it the true force.
#pragma once

#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "common/result.h"
#include "common/rng.h"

namespace recruit::sim {

// Load-cell parameters, from a task file's "sensor" object. Both 0 = an exact sensor.
struct SensorParams {
  double noise_std = 0;   // N, standard deviation of the additive white noise
  double resolution = 0;  // N, quantisation step (0 = none)

  static Result<SensorParams> Create(double noise_std, double resolution);
  // {"noise_std": N, "resolution": N}; unknown keys and bad values are errors naming `where`.
  static Result<SensorParams> FromJson(const nlohmann::json& j, const std::string& where);
  nlohmann::json ToJson() const;
  // Variance of a reading about the true force (N^2): noise plus the quantisation's
  // resolution^2 / 12 (Sheppard), what an estimator adds to its own R.
  double Variance() const { return noise_std * noise_std + resolution * resolution / 12.0; }
};

class ForceSensor {
 public:
  // seed: the sensor's own noise stream (the run loop derives it from the run seed).
  static Result<ForceSensor> Create(const SensorParams& params, std::uint64_t seed);

  // The host calls this at its sampling instants (every dT): one fresh reading of `true_force`
  // (noise, then quantisation), which is held and returned. Advances the noise stream.
  double SampleAndHold(double true_force);
  // The reading held since the last sample (what the telemetry shows between instants); NaN
  // before the first sample.
  double held() const { return held_; }

  const SensorParams& params() const { return params_; }

 private:
  ForceSensor(const SensorParams& p, std::uint64_t seed) : params_(p), rng_(seed) {}

  SensorParams params_;
  Rng rng_;
  double held_ = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace recruit::sim
