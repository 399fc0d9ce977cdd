// AtomicFile: write an output file through a temporary sibling and rename it into place on
// Commit(), so a failed or interrupted run never leaves a half-written output. Temporary files
// are removed by the destructor and, once InstallTempFileCleanupOnSignals() ran, on SIGINT /
// SIGTERM / SIGHUP too.
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
  ErrorCode code() const { return ErrorCode::kIo; }  // when !ok(): an I/O failure
  Error failure() const { return IoError(error_); }
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
  int slot_ = -1;  // in the signal-cleanup registry
};

// Removes every live temporary file (AtomicFile's, and paths registered below) when the process
// gets SIGINT, SIGTERM or SIGHUP, then dies of that signal with its default action. Installed
// once by the `recruit` front end; signals the process ignores stay ignored.
void InstallTempFileCleanupOnSignals();

// Registers a temporary path for that cleanup (for files not written through AtomicFile, e.g.
// gnuplot's output); returns a slot for UnregisterTempFile (-1: not registered).
int RegisterTempFile(const std::string& path);
void UnregisterTempFile(int slot);

// Writes `contents` to `path` atomically.
Status WriteFileAtomically(const std::string& path, const std::string& contents);

// Reads a whole file, or an error naming it: bad input when the path names no file, else I/O
// (CodeOf, common/result.h).
Result<std::string> ReadFile(const std::string& path);

}  // namespace recruit
