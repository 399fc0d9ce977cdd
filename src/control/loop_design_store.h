// Loop designs kept between processes: a design (control/loop_design.h) is a pure function of
// its inputs, so one made by an earlier run is the one a new search would make. A sweep's shards
// on a cluster, or a user's repeated runs of a task, then design each loop once; a run's own
// memo (loop_design.cc) covers the runs of one process.
//
// An entry is keyed by the exact bits of every input (LoopDesignKey) and this build's code
// version (CodeVersion, which changes with any edit of the sources): it holds both in full,
// compared word for word (no hash is trusted), and the design's every number bit for bit. A
// missing, damaged or foreign entry is a miss. Entries are written to a temporary sibling and
// renamed into place (atomic on POSIX), so concurrent runs see a whole entry or none; two writers
// of one key write the same bytes.
//
// Folder: RECRUIT_DESIGN_CACHE, else $XDG_CACHE_HOME/recruit/designs, else
// ~/.cache/recruit/designs; RECRUIT_DESIGN_CACHE=off turns it off. File name: the FNV-1a 64 hash
// (common/content_hash.h) of the code version and key, .design.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "control/loop_design.h"

namespace recruit::control::design_store {

// The store's folder ("" = off or no home).
std::string Folder();

// The design stored under `key`, if a whole entry of this build holds it.
std::optional<LoopDesign> Load(const std::vector<std::uint64_t>& key);

// Stores `design` under `key` (best effort: a folder that cannot be written only costs the
// next process a search).
void Save(const std::vector<std::uint64_t>& key, const LoopDesign& design);

}  // namespace recruit::control::design_store
