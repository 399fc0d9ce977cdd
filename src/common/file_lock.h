// An exclusive advisory lock (flock) on a file, held for the object's life: one writer per
// output folder (a second `recruit sweep` into the same folder fails at once instead of racing).
#pragma once

#include <string>

#include "common/result.h"

namespace recruit {

class FileLock {
 public:
  // Creates `path` if needed and takes the lock without waiting; the error says the lock is
  // held by another process (and its pid, written into the file by the holder).
  static Result<FileLock> TryLock(const std::string& path);
  // The same, waiting for the holder to release it (e.g. one process identifies a cached model
  // while the others wait for the file).
  static Result<FileLock> Lock(const std::string& path);
  FileLock(FileLock&& o) noexcept : fd_(o.fd_) { o.fd_ = -1; }
  FileLock& operator=(FileLock&& o) noexcept;
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;
  ~FileLock();

 private:
  explicit FileLock(int fd) : fd_(fd) {}
  int fd_ = -1;
};

}  // namespace recruit
