// What an identified model was identified on, checked before a model is used: a model is
// never used on a plant it does not describe. MuJoCo-free; identification/plant_record.h makes the
// record from a model's bundle.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "common/result.h"
#include "plugin/unit_model.h"

namespace recruit::control {

// The unit parameters that decide the per-unit transient and force law, as a JSON object.
nlohmann::json UnitRecord(const sma::UnitParams& u);

// FNV-1a 64 of the record's "unit" object as canonical JSON text.
std::string PlantHash(const nlohmann::json& unit);

// Checks a model file's "identification.plant" against `plant` (a PlantRecord). A model without
// a record passes (e.g. fitted from a log: its plant is unknown). A different hash is an error
// naming the model file's plant and this one and the unit parameters that differ.
Status CheckModelPlant(const std::string& model_file, const nlohmann::json& plant);
// The same for the file's content, already parsed (`model`); `model_file` names it in messages.
Status CheckModelPlant(const std::string& model_file, const nlohmann::json& model,
                       const nlohmann::json& plant);

}  // namespace recruit::control
