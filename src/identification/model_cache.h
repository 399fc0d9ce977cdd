// Where the estimator's identified models are found, and made when missing: a model is keyed
// by the plant it describes (its unit's hash and the limb it is identified on, PlantRecord's
// "limb"), the bundle's actuator, dT and its number of states, e.g.
// "flexor_3f2a9c0d12ab45ef_0c1d2e3f4a5b6c7d_dt0.5_m20.json". Looked up, in order, in the folders of
// RECRUIT_MODEL_PATH (colon-separated), the shipped models/identified/ (under the data folder
// the program set, common/data_path.h; none when it set none) and the user's cache
// (RECRUIT_MODEL_CACHE, else $XDG_CACHE_HOME/recruit/models, else ~/.cache/recruit/models).
// When none holds it, it is identified on the plant (plant_identification.h) and written to the
// cache, under a lock, so that concurrent runs identify it once. A cached model records the
// identification version it was made with ("identification.version"); one of another version
// is made again, not used.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/result.h"
#include "control/sampling_period.h"
#include "identification/plant_identification.h"

namespace recruit::identification {

// "<actuator>_<hash>_<limb>_dt<dT>_m<states>.json" for a PlantRecord `plant`; without the limb
// part when `limb` is false or the record has none. The folders before the cache may hold a
// model named without it (one made for the bundle's units on any limb): used when none of this
// limb's is there. The cache's are always the limb's.
std::string ModelFileName(const nlohmann::json& plant, double dT, int num_states, bool limb = true);

// The folders searched, in order; the last is the cache.
std::vector<std::string> ModelSearchPath();

struct ModelRequest {
  std::string model_path;  // the MJCF the plant is loaded from
  std::string actuator;    // the bundle
  nlohmann::json plant;    // its PlantRecord
  double dT = control::kDefaultDT;
  int num_states = 20;
};

// Whether the model file at `path` was made by this build's identification
// (kIdentificationVersion).
bool MadeByThisIdentification(const std::string& path);

// The model file for the request: found on the search path, or identified and cached when
// `identify` is true (else an error saying how to make one). `log` (may be null) is told when
// an identification starts, as it takes a while (seconds to a minute).
Result<std::string> FindOrIdentifyModel(const ModelRequest& request, bool identify, std::FILE* log);

}  // namespace recruit::identification
