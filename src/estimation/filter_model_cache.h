// ParseFilterModelFile: a filter-model file read and parsed once per process for each content.
// A sweep builds the controllers of every run from the same few files, and parsing one (16 kB of
// JSON into a FilterModel) was 1.3 M of a short run's 3.3 M instructions. The key is the path
// (messages name it) and the file's exact bytes, compared in full, so an edited file is parsed
// again; the file is read at every call. Thread-safe (sweeps build runs on several threads).
#pragma once

#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "common/result.h"
#include "estimation/filter_model.h"

namespace recruit::estimation {

struct ParsedFilterModelFile {
  nlohmann::json json;  // the file's JSON (ParseJsonText, common/json_file.h)
  FilterModel model;    // FilterModel::FromJsonValue(json, path)
};

// The file at `path` as it reads now: its JSON and model, the same as parsing it afresh (the
// same errors too: a failure is not kept). Up to kFilterModelCacheEntries contents are kept, the
// least recently used dropped first.
inline constexpr int kFilterModelCacheEntries = 16;
Result<std::shared_ptr<const ParsedFilterModelFile>> ParseFilterModelFile(const std::string& path);

}  // namespace recruit::estimation
