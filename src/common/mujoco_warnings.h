// MuJoCo's warnings (the plugin's design and fit checks among them) on stderr, each text once per
// process (a model compiled several times warns as often), and never into MUJOCO_LOG.TXT in the
// working folder, which MuJoCo's default handler appends to: a program writes only its outputs.
// Header-only: the includer links mujoco::mujoco.
#pragma once

#include <mujoco/mujoco.h>

#include <cstdio>
#include <mutex>
#include <set>
#include <string>

namespace recruit {

inline void WarnOnceOnStderr(const char* message) {
  static std::mutex mutex;
  static std::set<std::string> said;
  std::lock_guard<std::mutex> lock(mutex);
  if (said.insert(message).second) std::fprintf(stderr, "WARNING: %s\n", message);
}

// Makes WarnOnceOnStderr MuJoCo's warning handler, unless the program has one already (e.g. a
// Python session whose other libraries set it).
inline void InstallMujocoWarnings() {
  if (mju_user_warning == nullptr) mju_user_warning = WarnOnceOnStderr;
}

// While alive, MuJoCo's warnings are dropped: e.g. attach's compiles of intermediate copies
// (the model before its locks, whose bundles' fit check would warn of joints the locks will
// hold). The handler is process-wide: only where no other thread compiles a model meanwhile. The
// handler in force before is restored.
class QuietMujocoWarnings {
 public:
  QuietMujocoWarnings() : saved_(mju_user_warning) {
    mju_user_warning = [](const char*) {};
  }
  ~QuietMujocoWarnings() { mju_user_warning = saved_; }
  QuietMujocoWarnings(const QuietMujocoWarnings&) = delete;
  QuietMujocoWarnings& operator=(const QuietMujocoWarnings&) = delete;

 private:
  void (*saved_)(const char*);
};

}  // namespace recruit
