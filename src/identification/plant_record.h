// PlantRecord: what an identified model was identified on, so that a model is never used on a
// plant it does not describe. The record names the bundle (model file, actuator, tendon, N), its
// unit parameters and settled unit force, and a hash over the unit parameters that decide the
// per-unit transient (not N: a per-unit model is rescaled to any N, FilterModel::WithPopulation).
#pragma once

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "common/mujoco_ptr.h"
#include "common/result.h"
#include "control/model_plant.h"
#include "plugin/sma_host.h"

namespace recruit::identification {

// {"model": ..., "actuator": ..., "tendon": ..., "num_units": N, "settled_unit_force_N": f,
//  "unit": {key: value, ...}, "hash": "16 hex digits", "limb": "16 hex digits"}. "limb" is
// LimbHash(model_path): identification runs on the limb (its tendon's lengths and poses), so the
// model cache keys its files by it too.
nlohmann::json PlantRecord(const sma::SmaHost& host, int bundle, const std::string& model_path);

// FNV-1a 64 (common/content_hash.h) of the MJCF file's bytes (not of the files it includes or
// the meshes it names), "" when it cannot be read.
std::string LimbHash(const std::string& model_path);

// An MJCF model loaded with MuJoCo, its SMA host and the index of one of its bundles.
struct LoadedBundle {
  ModelPtr model;
  std::unique_ptr<sma::SmaHost> host;
  int bundle = -1;
};
// The bundle on actuator `actuator` (empty: the first) of the model at `model_path`; errors name
// the file and the bundles it has.
Result<LoadedBundle> LoadBundle(const std::string& model_path, const std::string& actuator);

// The PlantRecord of that bundle.
Result<nlohmann::json> PlantRecordOf(const std::string& model_path, const std::string& actuator);

}  // namespace recruit::identification
