// Loading MJCF from a file or from a string (MuJoCo's VFS: mj_addBufferVFS), with MuJoCo's own
// compiler error in the message.
#pragma once

#include <mujoco/mujoco.h>

#include <memory>
#include <string>

#include "common/mujoco_ptr.h"
#include "common/result.h"

namespace recruit {

inline Result<ModelPtr> LoadModel(const std::string& path) {
  char error[1000] = "";
  ModelPtr m(mj_loadXML(path.c_str(), nullptr, error, sizeof error));
  if (!m) return Error{"cannot load '" + path + "': " + error};
  return m;
}

// `xml` compiled as if it were the file `name` (relative includes and assets are not found).
inline Result<ModelPtr> LoadModelFromString(const std::string& xml,
                                            const std::string& name = "model.xml") {
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  mj_addBufferVFS(vfs.get(), name.c_str(), xml.data(), static_cast<int>(xml.size()));
  char error[1000] = "";
  ModelPtr m(mj_loadXML(name.c_str(), vfs.get(), error, sizeof error));
  mj_deleteVFS(vfs.get());
  if (!m) return Error{error};
  return m;
}

}  // namespace recruit
