// SwitchingLog: an identification record, one row per control instant k (every dT):
//   time_k, the force y_k sampled at that instant, then the broadcast (p_on_k, p_off_k) sent
//   right after sampling. The bundle starts at rest with every unit off (cold).
// CSV form (header required, extra columns ignored):  time,p_on,p_off,force
#pragma once

#include <string>
#include <vector>

#include "common/result.h"

namespace recruit::control {

struct SwitchingLog {
  int num_units = 60;
  double dT = 0.5;  // s
  std::vector<double> time, p_on, p_off, force;
  std::vector<double> true_on;  // optional ground truth (debug interface); empty when unknown

  int size() const { return static_cast<int>(force.size()); }
  // Reads the CSV; dT is taken from the time column (uniform spacing checked).
  static Result<SwitchingLog> FromCsv(const std::string& path, int num_units);
  // Checks sizes, probabilities in [0, 1], finite forces, at least 2 rows.
  Status Validate(const std::string& where) const;
  Status SaveCsv(const std::string& path) const;  // atomically
};

}  // namespace recruit::control
