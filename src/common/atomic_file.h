// AtomicFile: write an output file through a temporary sibling and rename it into place on
// Commit(), so a failed or interrupted run never leaves a half-written output.
#pragma once

#include <fstream>
#include <string>

#include "common/result.h"

namespace recruit {

class AtomicFile {
 public:
  // Opens `path`.tmp.<pid> for writing. Check ok() / error() before use.
  explicit AtomicFile(std::string path, std::ios::openmode mode = std::ios::out);
  ~AtomicFile();  // Removes the temporary file unless Commit() succeeded.
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }
  std::ofstream& stream() { return out_; }
  const std::string& path() const { return path_; }
  const std::string& temp_path() const { return temp_path_; }

  // Flushes, closes and renames the temporary file onto the final path.
  Status Commit();

 private:
  std::string path_;
  std::string temp_path_;
  std::ofstream out_;
  std::string error_;
  bool committed_ = false;
};

// Writes `contents` to `path` atomically.
Status WriteFileAtomically(const std::string& path, const std::string& contents);

// Reads a whole file, or an error naming it.
Result<std::string> ReadFile(const std::string& path);

}  // namespace recruit
