// Where the project's caches live (identified models, compiled models, loop designs): the
// folder a variable names (RECRUIT_..._CACHE), else $XDG_CACHE_HOME/recruit/<leaf>, else
// ~/.cache/recruit/<leaf>.
#pragma once

#include <cstdlib>
#include <string>

namespace recruit {

// `variable`'s value when set and not empty, else the user's cache folder for `leaf`; "" when
// there is none (no XDG_CACHE_HOME and no HOME).
inline std::string CacheFolder(const char* variable, const char* leaf) {
  if (const char* c = std::getenv(variable); c && *c) return c;
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) {
    return std::string(x) + "/recruit/" + leaf;
  }
  if (const char* h = std::getenv("HOME"); h && *h) {
    return std::string(h) + "/.cache/recruit/" + leaf;
  }
  return "";
}

}  // namespace recruit
