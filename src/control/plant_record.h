// PlantRecord: what an identified model was identified on, so that a model is never used on a
// plant it does not describe. The record names the bundle (model file, actuator, tendon, N), its
// unit parameters and settled unit force, and a hash over the unit parameters that decide the
// per-unit transient (not N: a per-unit model is rescaled to any N, FilterModel::WithPopulation).
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "common/result.h"
#include "plugin/sma_host.h"

namespace recruit::control {

// {"model": ..., "actuator": ..., "tendon": ..., "num_units": N, "settled_unit_force_N": f,
//  "unit": {key: value, ...}, "hash": "16 hex digits"}.
nlohmann::json PlantRecord(const sma::SmaHost& host, int bundle, const std::string& model_path);

// FNV-1a 64 of the record's "unit" object as canonical JSON text.
std::string PlantHash(const nlohmann::json& unit);

// Checks a model file's "identification.plant" against `plant` (a PlantRecord). A model without
// a record passes (e.g. fitted from a log: its plant is unknown). A different hash is an error
// naming the model file's plant and this one and the unit parameters that differ.
Status CheckModelPlant(const std::string& model_file, const nlohmann::json& plant);

}  // namespace recruit::control
