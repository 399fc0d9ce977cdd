#include "cli/command_modules.h"

#include <dlfcn.h>
#include <unistd.h>

#include <climits>

namespace recruit::cli {
namespace {

std::string BinaryDir() {
  char path[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", path, sizeof(path) - 1);
  if (n <= 0) return ".";
  std::string p(path, static_cast<size_t>(n));
  const size_t slash = p.rfind('/');
  return slash == std::string::npos ? "." : p.substr(0, slash);
}

}  // namespace

void* OpenCommandModule(const std::string& file, std::string* error) {
  const std::string path = BinaryDir() + "/" + file;
  void* module = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!module) {
    const char* why = ::dlerror();
    *error = "cannot open the module '" + path +
             "' (it is built with `recruit`): " + (why ? why : "unknown error");
  }
  return module;
}

void* ModuleSymbol(void* module, const char* name, std::string* error) {
  void* sym = ::dlsym(module, name);
  if (!sym) *error = std::string("the module has no entry point '") + name + "' (a stale build?)";
  return sym;
}

const PlotModule* OpenPlotModule(std::string* error) {
  static PlotModule module;
  static std::string open_error;
  static const bool opened = [] {
    void* m = OpenCommandModule("librecruit-plot.so", &open_error);
    if (!m) return false;
    module.run =
        reinterpret_cast<RecruitPlotRunFn>(ModuleSymbol(m, "recruit_plot_run", &open_error));
    module.figure =
        reinterpret_cast<RecruitPlotFigureFn>(ModuleSymbol(m, "recruit_plot_figure", &open_error));
    return module.run && module.figure;
  }();
  if (!opened) *error = open_error;
  return opened ? &module : nullptr;
}

}  // namespace recruit::cli
