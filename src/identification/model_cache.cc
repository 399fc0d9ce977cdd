#include "identification/model_cache.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "common/atomic_file.h"
#include "common/cache_folder.h"
#include "common/data_path.h"
#include "common/file_lock.h"
#include "common/json_file.h"

namespace recruit::identification {
namespace fs = std::filesystem;

std::string ModelFileName(const nlohmann::json& plant, double dT, int num_states, bool limb) {
  char dt[32];
  std::snprintf(dt, sizeof dt, "%g", dT);
  const std::string limb_hash = limb ? plant.value("limb", std::string()) : std::string();
  return plant.value("actuator", std::string("bundle")) + "_" +
         plant.value("hash", std::string("unknown")) + (limb_hash.empty() ? "" : "_" + limb_hash) +
         "_dt" + dt + "_m" + std::to_string(num_states) + ".json";
}

std::vector<std::string> ModelSearchPath() {
  std::vector<std::string> dirs;
  if (const char* p = std::getenv("RECRUIT_MODEL_PATH"); p && *p) {
    std::string all = p;
    for (size_t start = 0; start <= all.size();) {
      const size_t end = std::min(all.find(':', start), all.size());
      if (end > start) dirs.push_back(all.substr(start, end - start));
      start = end + 1;
    }
  }
  if (const std::string data = DataDir(); !data.empty()) {
    dirs.push_back(data + "/models/identified");
  }
  const std::string cache = CacheFolder("RECRUIT_MODEL_CACHE", "models");
  dirs.push_back(cache.empty() ? (fs::temp_directory_path() / "recruit-models").string() : cache);
  return dirs;
}

bool MadeByThisIdentification(const std::string& path) {
  auto j = LoadJsonFile(path);
  if (!j.ok() || !j->is_object()) return false;
  const auto id = j->find("identification");
  if (id == j->end() || !id->is_object()) return false;
  const auto v = id->find("version");
  return v != id->end() && v->is_number_integer() && v->get<int>() == kIdentificationVersion;
}

Result<std::string> FindOrIdentifyModel(const ModelRequest& r, bool identify, std::FILE* log) {
  const std::string name = ModelFileName(r.plant, r.dT, r.num_states);
  const std::vector<std::string> dirs = ModelSearchPath();
  std::error_code ec;
  // The folders before the cache hold models put there on purpose: taken as they are. The
  // cache's were made on demand: only one this build would make is used.
  // Those folders may also hold a model named without the limb (made for the bundle's units on
  // any limb): in each, taken when none of this limb's is there. The cache's are this limb's.
  const std::string any_limb = ModelFileName(r.plant, r.dT, r.num_states, /*limb=*/false);
  for (size_t i = 0; i < dirs.size(); ++i) {
    const bool cache = i + 1 == dirs.size();
    for (const std::string& n : {name, any_limb}) {
      const fs::path f = fs::path(dirs[i]) / n;
      if (!fs::exists(f, ec)) continue;
      if (!cache) return f.string();
      if (n == name && MadeByThisIdentification(f.string())) return f.string();
    }
  }
  if (!identify) {
    return Error{"no identified model " + name + " on the model search path (" + dirs.front() +
                 (dirs.size() > 1 ? ", ..." : "") + "); identify one: recruit identify --bench " +
                 r.model_path + " --actuator " + r.actuator + " --dt DT"};
  }
  const fs::path cache = dirs.back();
  fs::create_directories(cache, ec);
  if (ec) return Error{"model cache " + cache.string() + ": " + ec.message(), CodeOf(ec)};
  const fs::path file = cache / name;
  auto lock = FileLock::Lock((cache / (name + ".lock")).string());
  if (!lock) return Error{lock.error(), lock.code()};
  // Made while we waited?
  if (fs::exists(file, ec) && MadeByThisIdentification(file.string())) return file.string();
  if (log) {
    std::fprintf(log, "recruit: identifying the %s model for dT = %g s on %s (cached as %s)\n",
                 r.actuator.c_str(), r.dT, r.model_path.c_str(), file.string().c_str());
  }
  PlantIdentificationOptions o;
  o.dT = r.dT;
  o.num_states = r.num_states;
  auto id = IdentifyOnPlant(r.model_path, r.actuator, o, "identified on demand (model cache)");
  if (!id)
    return Error{"identifying a model for dT = " + std::to_string(r.dT) + " s: " + id.error(),
                 id.code()};
  if (Status s = WriteFileAtomically(file.string(), id->model.dump(2) + "\n"); !s) {
    return Error{s.error(), s.code()};
  }
  return file.string();
}

}  // namespace recruit::identification
