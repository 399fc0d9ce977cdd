// SwitchingLog: an identification record, one row per control instant k (every dT):
//   time_k, the force y_k sampled at that instant, then the broadcast (p_on_k, p_off_k) sent
//   right after sampling. The bundle starts at rest with every unit off (cold).
// CSV form (header required, extra columns ignored):  time,p_on,p_off,force
//   optional: true_on (units on at the instant, before the broadcast), realized_on,
//   realized_off (the fraction of the off units that did switch on, of the on units that did
//   switch off, at the broadcast: known on a bench through the plugin's per-unit debug state).
// A bench log (estimation/bench_log.h, docs/formats/bench_log.md) is read too: its control
// instants are the rows, the chosen bundle's sensed_force the force.
// When the realized fractions are present the fit uses them as the inputs: the prediction is
// then conditioned on how many units did switch, without the binomial noise of the draw.
#pragma once

#include <string>
#include <vector>

#include "common/result.h"
#include "control/sampling_period.h"

namespace recruit::identification {

struct SwitchingLog {
  int num_units = 60;
  double dT = control::kDefaultDT;  // s
  std::vector<double> time, p_on, p_off, force;
  std::vector<double> true_on;  // optional ground truth (debug interface); empty when unknown
  std::vector<double> realized_on, realized_off;  // optional, see above; empty when unknown

  bool has_realized() const { return !realized_on.empty(); }
  // The switching fractions the fit uses at instant k: realized when known, else broadcast.
  double InputOn(int k) const { return has_realized() ? realized_on[k] : p_on[k]; }
  double InputOff(int k) const { return has_realized() ? realized_off[k] : p_off[k]; }

  int size() const { return static_cast<int>(force.size()); }
  // Reads the CSV; dT is taken from the time column (uniform spacing checked). `bundle`: a bench
  // log's bundle (empty: its only one); the older format has one bundle and ignores it.
  static Result<SwitchingLog> FromCsv(const std::string& path, int num_units,
                                      const std::string& bundle = "");
  // Checks sizes, probabilities in [0, 1], finite forces, at least 2 rows.
  Status Validate(const std::string& where) const;
  Status SaveCsv(const std::string& path) const;  // atomically
};

}  // namespace recruit::identification
