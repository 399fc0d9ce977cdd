// PlantRecord: what an identified model was identified on, so that a model is never used on a
// plant it does not describe. The record names the bundle (model file, actuator, tendon, N), its
// unit parameters and settled unit force, and a hash over the unit parameters that decide the
// per-unit transient (not N: a per-unit model is rescaled to any N, FilterModel::WithPopulation).
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "common/result.h"
#include "control/model_plant.h"
#include "plugin/sma_host.h"

namespace recruit::control {

// {"model": ..., "actuator": ..., "tendon": ..., "num_units": N, "settled_unit_force_N": f,
//  "unit": {key: value, ...}, "hash": "16 hex digits"}.
nlohmann::json PlantRecord(const sma::SmaHost& host, int bundle, const std::string& model_path);

// The record of the bundle on actuator `actuator` (empty: the first) of the MJCF model at
// `model_path`, loaded with MuJoCo; errors name the file and the bundles it has.
Result<nlohmann::json> PlantRecordOf(const std::string& model_path, const std::string& actuator);

}  // namespace recruit::control
