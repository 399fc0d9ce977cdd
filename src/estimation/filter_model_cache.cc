#include "estimation/filter_model_cache.h"

#include <iterator>
#include <list>
#include <mutex>
#include <utility>

#include "common/atomic_file.h"
#include "common/json_file.h"

namespace recruit::estimation {
namespace {

struct Entry {
  std::string path, bytes;
  std::shared_ptr<const ParsedFilterModelFile> parsed;
};

// Most recently used first; a few entries, so a linear search (path, then size and bytes).
std::mutex cache_mutex;
std::list<Entry> cache;

std::shared_ptr<const ParsedFilterModelFile> Find(const std::string& path,
                                                  const std::string& bytes) {
  for (auto it = cache.begin(); it != cache.end(); ++it) {
    if (it->path == path && it->bytes == bytes) {
      cache.splice(cache.begin(), cache, it);
      return cache.front().parsed;
    }
  }
  return nullptr;
}

}  // namespace

Result<std::shared_ptr<const ParsedFilterModelFile>> ParseFilterModelFile(const std::string& path) {
  auto text = ReadFile(path);
  if (!text.ok()) return text.failure();
  {
    std::lock_guard<std::mutex> lock(cache_mutex);
    if (auto hit = Find(path, *text)) return hit;
  }
  // Parsed outside the lock: threads parsing the same new file at once each get a whole parse.
  auto j = ParseJsonText(*text, path);
  if (!j.ok()) return j.failure();
  auto model = FilterModel::FromJsonValue(*j, path);
  if (!model.ok()) return model.failure();
  auto parsed = std::make_shared<const ParsedFilterModelFile>(
      ParsedFilterModelFile{std::move(j).value(), std::move(model).value()});
  std::lock_guard<std::mutex> lock(cache_mutex);
  if (auto hit = Find(path, *text)) return hit;  // another thread was first: one entry
  cache.push_front({path, std::move(text).value(), parsed});
  if (static_cast<int>(cache.size()) > kFilterModelCacheEntries) cache.pop_back();
  return parsed;
}

}  // namespace recruit::estimation
