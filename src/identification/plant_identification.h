// Identification of an estimator model on a MuJoCo plant, the one pipeline behind
// `recruit identify --bench` and the model cache (identification/model_cache.h):
//   1. record a switching log with the limb held where the bundle's tendon is longest
//      (bench_recorder.h), through the plugin's exact force (the load cell's own noise is added
//      by the estimator, from the task's sensor);
//   2. fit the transient chain and its forces there (identification.h);
//   3. give each state the martensite fraction whose force law gives its force there
//      (control/unit_force_map.h), so that the model's H follows the tendon's length;
//   4. check that on fresh recordings held at other lengths: the predicted mean force's R^2 and
//      RMSE at each, stored in the model file's "identification.length_checks".
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/result.h"
#include "control/sampling_period.h"
#include "identification/identification.h"

namespace recruit::identification {

// The version of what IdentifyOnPlant makes, recorded in each model as
// "identification.version": raise it whenever a change to the recording, the fit or the export
// changes the model it makes, so that models cached by an older build are made again
// (model_cache.h).
constexpr int kIdentificationVersion = 9;

struct PlantIdentificationOptions {
  double dT = control::kDefaultDT;  // s
  int num_states = 20;              // even, >= 4
  double duration = 900;            // s recorded for the fit
  double settle = 8;                // s a unit takes to settle (the excitation's holds)
  double holdout = 0.3;             // last fraction of the log held out
  double smoothness = 1e-3;
  std::uint64_t seed = 1;
  // Places in the tendon's length range (0 shortest, 1 longest) of the check recordings.
  std::vector<double> check_places = {0.0, 0.5};
  double check_duration = 300;  // s per check
  // A further check with the joint driven over its range and back with this period (s).
  double sweep_period = 20;
};

struct LengthCheck {
  std::string pose;
  double tendon_length = 0;  // m
  FitMetrics fit;
};

struct PlantIdentification {
  IdentificationResult fit;
  std::vector<LengthCheck> checks;
  SwitchingLog log;      // the fit's recording
  nlohmann::json model;  // the model file's contents (FilterModel JSON + "identification")
};

// `actuator` empty: the model's first bundle. `command` is recorded in the file.
Result<PlantIdentification> IdentifyOnPlant(const std::string& model_path,
                                            const std::string& actuator,
                                            const PlantIdentificationOptions& options,
                                            const std::string& command);

// The record of a fit's quality: {"samples", "rmse_N", "r2"}.
nlohmann::json MetricsJson(const FitMetrics& m);

}  // namespace recruit::identification
