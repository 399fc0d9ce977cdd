#include "common/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <sstream>

namespace recruit {
namespace {

// Registry of live temporary files, read by the signal handler. Fixed storage and lock-free
// slot states, so the handler only reads memory and calls unlink (async-signal-safe).
constexpr int kSlots = 256;
constexpr size_t kPathMax = 4096;
enum : int { kFree = 0, kFilling = 1, kLive = 2 };
std::atomic<int> slot_state[kSlots];
char slot_path[kSlots][kPathMax];

void CleanupHandler(int sig) {
  for (int i = 0; i < kSlots; ++i) {
    if (slot_state[i].load(std::memory_order_acquire) == kLive) ::unlink(slot_path[i]);
  }
  // Die of the same signal with its default action, so the parent sees the real cause.
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

std::once_flag handlers_once;

}  // namespace

int RegisterTempFile(const std::string& path) {
  if (path.size() >= kPathMax) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int expected = kFree;
    if (slot_state[i].compare_exchange_strong(expected, kFilling, std::memory_order_acq_rel)) {
      std::memcpy(slot_path[i], path.c_str(), path.size() + 1);
      slot_state[i].store(kLive, std::memory_order_release);
      return i;
    }
  }
  return -1;  // full: the file is still removed by its destructor, only not on a signal
}

void UnregisterTempFile(int slot) {
  if (slot >= 0 && slot < kSlots) slot_state[slot].store(kFree, std::memory_order_release);
}

void InstallTempFileCleanupOnSignals() {
  std::call_once(handlers_once, [] {
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
      struct sigaction old {};
      ::sigaction(sig, nullptr, &old);
      if (old.sa_handler == SIG_IGN) continue;  // e.g. nohup: keep ignoring
      struct sigaction sa {};
      sa.sa_handler = CleanupHandler;
      sigemptyset(&sa.sa_mask);
      sa.sa_flags = SA_RESETHAND;
      ::sigaction(sig, &sa, nullptr);
    }
  });
}

AtomicFile::AtomicFile(std::string path, std::ios::openmode mode)
    : path_(std::move(path)), temp_path_(path_ + ".tmp." + std::to_string(::getpid())) {
  slot_ = RegisterTempFile(temp_path_);  // before the file exists: a signal now unlinks nothing
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
  UnregisterTempFile(slot_);
}

Status AtomicFile::Commit() {
  if (!ok()) return IoError(error_);
  out_.flush();
  const bool good = out_.good();
  out_.close();  // close() flushes the last buffer: a full disk can show only here
  if (!good || out_.fail()) {
    return Error{"cannot write '" + path_ + "': the write failed (disk full or file too large?)",
                 ErrorCode::kIo};
  }
  if (std::rename(temp_path_.c_str(), path_.c_str()) != 0) {
    return Error{"cannot rename '" + temp_path_ + "' to '" + path_ + "': " + std::strerror(errno),
                 ErrorCode::kIo};
  }
  committed_ = true;
  UnregisterTempFile(slot_);
  slot_ = -1;
  return Status::Ok();
}

Status WriteFileAtomically(const std::string& path, const std::string& contents) {
  AtomicFile f(path, std::ios::binary);
  if (!f.ok()) return Error{f.error(), f.code()};
  f.stream() << contents;
  return f.Commit();
}

Result<std::string> ReadFile(const std::string& path) {
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int err = errno;
    return Error{"cannot open '" + path + "': " + std::strerror(err), CodeOfErrno(err)};
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) return Error{"cannot read '" + path + "'", ErrorCode::kIo};
  return ss.str();
}

}  // namespace recruit
