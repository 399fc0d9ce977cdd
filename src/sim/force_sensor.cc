#include "sim/force_sensor.h"

#include <cmath>

#include "common/short_text.h"

namespace recruit::sim {
Result<SensorParams> SensorParams::Create(double noise_std, double resolution) {
  if (!(noise_std >= 0 && std::isfinite(noise_std))) {
    return Error{"noise_std must be a finite number >= 0 N, got " + std::to_string(noise_std)};
  }
  if (!(resolution >= 0 && std::isfinite(resolution))) {
    return Error{"resolution must be a finite number >= 0 N, got " + std::to_string(resolution)};
  }
  return SensorParams{noise_std, resolution};
}

Result<SensorParams> SensorParams::FromJson(const nlohmann::json& j, const std::string& where) {
  if (!j.is_object()) {
    return Error{where + ": must be an object {\"noise_std\": N, \"resolution\": N}, got " +
                 ShortText(j.dump())};
  }
  SensorParams p;
  for (const auto& [key, value] : j.items()) {
    double* field = key == "noise_std"    ? &p.noise_std
                    : key == "resolution" ? &p.resolution
                                          : nullptr;
    if (!field) {
      return Error{where + "." + key + ": unknown key; allowed: noise_std, resolution"};
    }
    if (!value.is_number() || !(value.get<double>() >= 0) || !std::isfinite(value.get<double>())) {
      return Error{where + "." + key + ": must be a number >= 0 (N), got " +
                   ShortText(value.dump())};
    }
    *field = value.get<double>();
  }
  return p;
}

nlohmann::json SensorParams::ToJson() const {
  return {{"noise_std", noise_std}, {"resolution", resolution}};
}

Result<ForceSensor> ForceSensor::Create(const SensorParams& params, std::uint64_t seed) {
  auto p = SensorParams::Create(params.noise_std, params.resolution);
  if (!p.ok()) return Error{"sensor: " + p.error(), p.code()};
  return ForceSensor(*p, seed);
}

double ForceSensor::SampleAndHold(double true_force) {
  double y = true_force;
  if (params_.noise_std > 0) y += params_.noise_std * rng_.Gaussian();
  if (params_.resolution > 0) y = params_.resolution * std::round(y / params_.resolution);
  held_ = y;
  return y;
}

}  // namespace recruit::sim
