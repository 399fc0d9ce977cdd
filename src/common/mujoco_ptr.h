// Owning pointers for MuJoCo's model and data, so that every early return frees them.
#pragma once

#include <mujoco/mujoco.h>

#include <memory>

namespace recruit {

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;
using DataPtr = std::unique_ptr<mjData, DataDeleter>;

}  // namespace recruit
