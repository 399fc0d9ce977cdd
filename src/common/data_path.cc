#include "common/data_path.h"

#include <cstdlib>
#include <mutex>
#include <utility>

namespace recruit {
namespace {

std::mutex& Mutex() {
  static std::mutex mu;
  return mu;
}
std::string& Dir() {
  static std::string dir;
  return dir;
}

}  // namespace

void SetDataDir(std::string dir) {
  std::lock_guard<std::mutex> lock(Mutex());
  Dir() = std::move(dir);
}

std::string DataDir() {
  if (const char* env = std::getenv("RECRUIT_DATA_DIR"); env != nullptr && *env != '\0') {
    return env;
  }
  std::lock_guard<std::mutex> lock(Mutex());
  return Dir();
}

}  // namespace recruit
