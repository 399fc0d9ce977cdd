#include "common/atomic_file.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <sstream>

namespace recruit {

AtomicFile::AtomicFile(std::string path, std::ios::openmode mode)
    : path_(std::move(path)), temp_path_(path_ + ".tmp." + std::to_string(::getpid())) {
  out_.open(temp_path_, mode | std::ios::out | std::ios::trunc);
  if (!out_) {
    error_ = "cannot write '" + path_ + "': " + std::strerror(errno);
  }
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    if (out_.is_open()) out_.close();
    std::remove(temp_path_.c_str());
  }
}

Status AtomicFile::Commit() {
  if (!ok()) return Error{error_};
  out_.flush();
  const bool good = out_.good();
  out_.close();
  if (!good) return Error{"write to '" + path_ + "' failed (disk full?)"};
  if (std::rename(temp_path_.c_str(), path_.c_str()) != 0) {
    return Error{"cannot rename '" + temp_path_ + "' to '" + path_ + "': " + std::strerror(errno)};
  }
  committed_ = true;
  return Status::Ok();
}

Status WriteFileAtomically(const std::string& path, const std::string& contents) {
  AtomicFile f(path, std::ios::binary);
  if (!f.ok()) return Error{f.error()};
  f.stream() << contents;
  return f.Commit();
}

Result<std::string> ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error{"cannot open '" + path + "': " + std::strerror(errno)};
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) return Error{"cannot read '" + path + "'"};
  return ss.str();
}

}  // namespace recruit
