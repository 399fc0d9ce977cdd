// A cache of compiled MuJoCo models (MuJoCo's binary mjb format), keyed exactly by what the
// compiled model depends on, so that a short run loads a model without parsing and compiling its
// XML (and without the spec edits the caller makes before compiling).
//
// Only models that read no other file are cached: an MJCF whose text has no `file...=` attribute
// (no include, mesh, texture, height field, skin or model asset). The compiled model then follows
// from its text, the caller's variant of the compile (e.g. "what only renders read is left out"),
// MuJoCo's version and this code's (CodeVersion), and the plugins' compile-time answers. An entry
// holds all of those but the last in full (the XML bytes too, compared byte for byte: no hash is
// trusted), this process's plugin registry (a model names its plugins by registry slot), the slot
// and name of each of the model's plugin instances (checked before MuJoCo loads the mjb: its
// validation needs every slot filled), and the mjb bytes. On a hit the plugins' state and sensor
// sizes are asked again (mjpPlugin::nstate, nsensordata) and must match the model's; any
// difference, a corrupt entry or a model MuJoCo cannot load is a miss, compiled afresh and
// written over. Entries are written to a temporary sibling and
// renamed into place (atomic on POSIX), so concurrent runs and threads see a whole entry or none;
// two writers of one key write the same bytes. The mjb bytes carry their size and hash: a damaged
// entry is a miss.
//
// What the compiler prints (MuJoCo's warnings) is printed by the run that compiles, not by the
// runs that load the entry; what the plugin prints at mj_makeData is printed by every run.
//
// Folder: RECRUIT_COMPILED_CACHE, else $XDG_CACHE_HOME/recruit/compiled, else
// ~/.cache/recruit/compiled; RECRUIT_COMPILED_CACHE=off turns the cache off. File name: the FNV-1a
// 64 hash (common/content_hash.h) of the entry's header and XML, .mjb.
// Header-only: the includer links mujoco::mujoco (recruit_common does not).
#pragma once

#include <fcntl.h>
#include <mujoco/mujoco.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "common/cache_folder.h"
#include "common/content_hash.h"

namespace recruit::compiled_cache {

// The cache's folder ("" = off or no home).
inline std::string Folder() {
  const std::string f = CacheFolder("RECRUIT_COMPILED_CACHE", "compiled");
  return f == "off" ? "" : f;
}

// True if the MJCF text names no other file (so its bytes determine the model).
inline bool ReadsNoOtherFile(std::string_view xml) {
  // Any attribute whose name starts with "file" (file, fileright, ...), wherever it is (a
  // comment too: a false alarm only costs the cache).
  auto word = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  for (std::size_t at = xml.find("file"); at != std::string_view::npos;
       at = xml.find("file", at + 1)) {
    if (at > 0 && word(xml[at - 1])) continue;
    std::size_t i = at + 4;
    while (i < xml.size() && word(xml[i])) ++i;
    while (i < xml.size() && std::isspace(static_cast<unsigned char>(xml[i]))) ++i;
    if (i < xml.size() && xml[i] == '=') return false;
  }
  return true;
}

// The name of the plugin registered at `slot` in this process, "?" for none.
inline std::string SlotName(int slot) {
  const mjpPlugin* p = slot >= 0 && slot < mjp_pluginCount() ? mjp_getPluginAtSlot(slot) : nullptr;
  return p != nullptr && p->name != nullptr ? p->name : "?";
}

// The entry's header: everything the compiled model depends on apart from the XML and plugins'
// answers, this process's plugin registry among it (a model names its plugins by slot, and
// processes register them in different orders: the Python package's MuJoCo has its own).
inline std::string Header(std::string_view variant) {
  std::string registry;
  for (int slot = 0; slot < mjp_pluginCount(); ++slot) registry += SlotName(slot) + ",";
  return std::string("recruit compiled model 2\n") + CodeVersion() + "\n" + mj_versionString() +
         "\n" + std::string(variant) + "\n" + registry + "\n";
}

// The slot and name of the plugin at each of the model's plugin instances, "slot:name,".
inline std::string PluginNames(const mjModel* m) {
  std::string names;
  for (int i = 0; i < m->nplugin; ++i) {
    names += std::to_string(m->plugin[i]) + ":" + SlotName(m->plugin[i]) + ",";
  }
  return names;
}

// True if every "slot:name," of `names` is registered here under that name: checked before
// MuJoCo loads the mjb, whose validation needs every slot it names filled.
inline bool SlotsRegistered(std::string_view names) {
  std::size_t at = 0;
  while (at < names.size()) {
    const std::size_t colon = names.find(':', at), comma = names.find(',', at);
    if (colon == std::string_view::npos || comma == std::string_view::npos || colon > comma) {
      return false;
    }
    const std::string slot(names.substr(at, colon - at));
    if (slot.empty() || slot.find_first_not_of("0123456789") != std::string::npos ||
        slot.size() > 6 ||
        SlotName(std::stoi(slot)) != names.substr(colon + 1, comma - colon - 1)) {
      return false;
    }
    at = comma + 1;
  }
  return true;
}

// True if every plugin instance of `m` (loaded from an entry) is the plugin it was compiled with
// and gives the state and sensor sizes it was compiled with.
inline bool PluginsAgree(const mjModel* m, std::string_view names) {
  if (PluginNames(m) != names) return false;
  for (int i = 0; i < m->nplugin; ++i) {
    const mjpPlugin* p = mjp_getPluginAtSlot(m->plugin[i]);
    const int n = p->nstate != nullptr ? p->nstate(m, i) : 0;
    if (n != m->plugin_statenum[i]) return false;
  }
  for (int j = 0; j < m->nsensor; ++j) {  // a plugin sensor's size is the plugin's answer too
    const int i = m->sensor_plugin[j];
    if (i < 0) continue;
    const mjpPlugin* p = mjp_getPluginAtSlot(m->plugin[i]);
    if (p->nsensordata == nullptr || p->nsensordata(m, i, j) != m->sensor_dim[j]) return false;
  }
  return true;
}

// The line before the mjb bytes: their size and FNV-1a 64 hash (a damaged entry is a miss).
inline std::string MjbLine(std::string_view mjb) {
  return std::to_string(mjb.size()) + " " + ContentHash().Add(mjb).Hex() + "\n";
}

// The whole file at `path`, or nullopt (read in one call: istreambuf_iterator costs ~60
// instructions a byte).
inline std::optional<std::string> ReadWhole(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return std::nullopt;
  std::string bytes;
  struct stat st;
  if (::fstat(fd, &st) == 0 && st.st_size > 0) bytes.reserve(static_cast<std::size_t>(st.st_size));
  char buf[65536];
  ssize_t n;
  while ((n = ::read(fd, buf, sizeof buf)) > 0) bytes.append(buf, static_cast<std::size_t>(n));
  ::close(fd);
  if (n < 0) return std::nullopt;
  return bytes;
}

inline std::string EntryPath(const std::string& folder, const std::string& header,
                             std::string_view xml) {
  return folder + "/" + ContentHash().Add(header).Add(xml).Hex() + ".mjb";
}

// The model from the entry at `path` if it is one for exactly (header, xml), else null.
inline mjModel* LoadEntry(const std::string& path, const std::string& header,
                          std::string_view xml) {
  const std::optional<std::string> read = ReadWhole(path);
  if (!read) return nullptr;
  const std::string& bytes = *read;
  // header, plugin slots and names + "\n", XML size + "\n", XML, MjbLine, mjb
  if (bytes.compare(0, header.size(), header) != 0) return nullptr;
  std::size_t at = header.size();
  const std::size_t names_end = bytes.find('\n', at);
  if (names_end == std::string::npos) return nullptr;
  const std::string names = bytes.substr(at, names_end - at);
  at = names_end + 1;
  const std::size_t size_end = bytes.find('\n', at);
  if (size_end == std::string::npos) return nullptr;
  if (bytes.substr(at, size_end - at) != std::to_string(xml.size())) return nullptr;
  at = size_end + 1;
  if (bytes.size() < at + xml.size() || bytes.compare(at, xml.size(), xml) != 0) return nullptr;
  at += xml.size();
  const std::size_t line_end = bytes.find('\n', at);
  if (line_end == std::string::npos) return nullptr;
  const std::string_view mjb = std::string_view(bytes).substr(line_end + 1);
  if (bytes.compare(at, line_end + 1 - at, MjbLine(mjb)) != 0) return nullptr;
  if (!SlotsRegistered(names)) return nullptr;
  mjModel* m = mj_loadModelBuffer(mjb.data(), static_cast<mjtSize>(mjb.size()));
  if (m != nullptr && !PluginsAgree(m, names)) {
    mj_deleteModel(m);
    return nullptr;
  }
  return m;
}

// Writes `bytes` to `path` through a uniquely named temporary sibling (mkstemp: threads of one
// process too), renamed into place; false on failure (nothing left behind).
inline bool WriteAtomically(const std::string& path, const std::string& bytes) {
  std::string temp = path + ".tmp.XXXXXX";
  const int fd = ::mkstemp(temp.data());
  if (fd < 0) return false;
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n <= 0) break;
    done += static_cast<std::size_t>(n);
  }
  const bool ok = ::close(fd) == 0 && done == bytes.size() && ::chmod(temp.c_str(), 0644) == 0 &&
                  std::rename(temp.c_str(), path.c_str()) == 0;
  if (!ok) ::unlink(temp.c_str());
  return ok;
}

// Writes the entry for (header, xml) holding `m`; failures are ignored (the cache is optional).
inline void StoreEntry(const std::string& folder, const std::string& path,
                       const std::string& header, std::string_view xml, const mjModel* m) {
  // The folder and its parents (mkdir -p); an existing folder is fine.
  for (std::size_t i = 1; i <= folder.size(); ++i) {
    if (i == folder.size() || folder[i] == '/') ::mkdir(folder.substr(0, i).c_str(), 0755);
  }
  std::string mjb(static_cast<std::size_t>(mj_sizeModel(m)), '\0');
  mj_saveModel(m, nullptr, mjb.data(), static_cast<mjtSize>(mjb.size()));
  std::string entry = header + PluginNames(m) + "\n" + std::to_string(xml.size()) + "\n";
  entry.append(xml.data(), xml.size());
  entry += MjbLine(mjb);
  entry += mjb;
  (void)WriteAtomically(path, entry);
}

// The model at `path` compiled by `compile` (mjModel* compile(char* error, int error_size), null
// on failure with the error written), or the cached compile of the same text and variant.
// `variant` names what the caller's compile does besides MuJoCo's own (it is part of the key).
template <class Compile>
mjModel* Load(const std::string& path, std::string_view variant, Compile compile, char* error,
              int error_size) {
  const std::string folder = Folder();
  if (folder.empty()) return compile(error, error_size);
  const std::optional<std::string> read = ReadWhole(path);
  if (!read) return compile(error, error_size);  // MuJoCo's own error names the file
  const std::string& xml = *read;
  if (!ReadsNoOtherFile(xml)) return compile(error, error_size);
  const std::string header = Header(variant);
  const std::string entry = EntryPath(folder, header, xml);
  if (mjModel* m = LoadEntry(entry, header, xml)) return m;
  mjModel* m = compile(error, error_size);
  if (m == nullptr) return m;
  // Stored only if the file still holds the text the key was made of (it may change meanwhile).
  if (ReadWhole(path) == xml) StoreEntry(folder, entry, header, xml, m);
  return m;
}

}  // namespace recruit::compiled_cache
