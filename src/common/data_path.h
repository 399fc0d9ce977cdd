// Where the data Recruit ships (models/identified/, ...) is found. No library compiles in a
// path: the program says where it is (the `recruit` CLI: the source tree it was built from; the
// Python package: the same, recorded at configure time), and RECRUIT_DATA_DIR overrides it.
// A library user who sets neither gets no shipped data: the model search path is then
// RECRUIT_MODEL_PATH and the cache (identification/model_cache.h).
#pragma once

#include <string>

namespace recruit {

// Sets the folder that holds models/ (the program's choice; call before any run starts).
void SetDataDir(std::string dir);

// RECRUIT_DATA_DIR when set and not empty, else the folder SetDataDir set, else "".
std::string DataDir();

}  // namespace recruit
