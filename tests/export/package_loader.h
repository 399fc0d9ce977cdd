// Test helpers for tests/export: write an exported package into a folder, compile it with the
// host C compiler into a shared library together with shim.c, and load it (dlopen), so that
// the test drives the generated C code of any precision and bundle count.
#pragma once

#include <dlfcn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "export/controller_export.h"

namespace recruit::exporter::testing {

// A fresh folder in this process's temporary folder, which is removed when the process exits.
inline std::filesystem::path FreshDir(const std::string& name) {
  struct Root {
    std::filesystem::path path = std::filesystem::temp_directory_path() /
                                 ("recruit_export_test_" + std::to_string(::getpid()));
    ~Root() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Root root;
  const auto dir = root.path / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline void WriteFiles(const std::vector<ExportedFile>& files, const std::filesystem::path& dir) {
  for (const ExportedFile& f : files) std::ofstream(dir / f.name, std::ios::binary) << f.contents;
}

// Runs a shell command; its exit status.
inline int Shell(const std::string& cmd) {
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : 128;
}

inline bool HasTool(const std::string& name) {
  return Shell("command -v " + name + " > /dev/null 2>&1") == 0;
}

// The host build's flags: ISO C (no contraction into fused multiply-adds), no fast math.
inline const char* HostCFlags() {
  return "-std=c99 -O2 -ffp-contract=off -fno-math-errno -Wall -Wextra -Werror";
}

// A compiled package behind shim.c's interface.
class LoadedController {
 public:
  // Compiles dir/recruit_controller.c with the shim into dir/libctl.so and loads it; an empty
  // error() when it worked.
  explicit LoadedController(const std::filesystem::path& dir) {
    const std::string so = (dir / "libctl.so").string();
    const std::string cmd =
        std::string(RECRUIT_HOST_CC) + " " + HostCFlags() + " -fPIC -shared -I" + dir.string() +
        " " + (dir / "recruit_controller.c").string() + " " +
        RECRUIT_SOURCE_DIR "/tests/export/shim.c -lm -o " + so + " 2> " + (dir / "cc.log").string();
    if (Shell(cmd) != 0) {
      std::ifstream log(dir / "cc.log");
      error_ = "compiling the package failed: " +
               std::string(std::istreambuf_iterator<char>(log), std::istreambuf_iterator<char>());
      return;
    }
    handle_ = dlopen(so.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle_) {
      error_ = dlerror();
      return;
    }
    size_ = reinterpret_cast<size_t (*)()>(dlsym(handle_, "shim_size"));
    bundles_ = reinterpret_cast<int (*)()>(dlsym(handle_, "shim_bundles"));
    init_ = reinterpret_cast<void (*)(void*)>(dlsym(handle_, "shim_init"));
    step_ = reinterpret_cast<void (*)(void*, const double*, double*)>(dlsym(handle_, "shim_step"));
    joints_ = reinterpret_cast<int (*)()>(dlsym(handle_, "shim_joints"));
    pose_ = reinterpret_cast<int (*)(const void*, int*)>(dlsym(handle_, "shim_pose"));
    if (!size_ || !bundles_ || !init_ || !step_ || !joints_ || !pose_) {
      error_ = "shim symbols missing";
      return;
    }
    ctx_.assign(size_(), 0);
    Init();
  }
  ~LoadedController() {
    if (handle_) dlclose(handle_);
  }
  LoadedController(const LoadedController&) = delete;
  LoadedController& operator=(const LoadedController&) = delete;

  const std::string& error() const { return error_; }
  int bundles() const { return bundles_(); }
  int joints() const { return joints_(); }
  // The self-tuned loops' reference pose of the last step (-1 without them) and whether the
  // references matched it exactly.
  int pose(bool* exact) const {
    int e = 0;
    const int p = pose_(ctx_.data(), &e);
    *exact = e != 0;
    return p;
  }
  size_t context_size() const { return size_(); }
  void Init() { init_(ctx_.data()); }
  // in: reference[nj], angle[nj], velocity[nj], force[nb], length[nb]; out: 5 per bundle (force
  // reference, p_on, p_off, estimated on, variance).
  void Step(const std::vector<double>& in, std::vector<double>& out) {
    out.resize(5 * bundles());
    step_(ctx_.data(), in.data(), out.data());
  }

 private:
  std::string error_;
  void* handle_ = nullptr;
  size_t (*size_)() = nullptr;
  int (*bundles_)() = nullptr;
  void (*init_)(void*) = nullptr;
  void (*step_)(void*, const double*, double*) = nullptr;
  int (*joints_)() = nullptr;
  int (*pose_)(const void*, int*) = nullptr;
  std::vector<unsigned char> ctx_;
};

}  // namespace recruit::exporter::testing
