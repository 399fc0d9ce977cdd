// The rendering commands' code lives in modules that `recruit` opens only when one of them runs
// (dlopen), so every other command starts without libav, OSMesa, LLVM and cairo
// (docs/rendering.md has the measured difference):
//   librecruit-render.so  `recruit render`: camera check, recorder (OSMesa/EGL, libav);
//   librecruit-plot.so    `recruit plot` and the figures of `recruit sweep` (cairo).
// They sit next to the `recruit` binary. Only the C entry points below cross the boundary; the
// structs passed are the ones both sides are compiled with (one build).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "common/step_observer.h"
#include "plot/figure.h"
#include "plot/plot_run.h"
#include "plot/render.h"
#include "render/video_recorder.h"

namespace recruit::cli {

// A running recorder as the command sees it: a step observer that can describe what it wrote.
class RenderSession : public StepObserver {
 public:
  // "N frames at F frames/s, WxH (GL driver)\n  wrote a.mp4, a.gif, ..." after Finish.
  virtual std::string Report() const = 0;
  bool Draws() const override { return true; }
};

struct RenderOpenRequest {
  render::VideoOptions video;
  std::string gl;          // --gl; empty = from the environment
  std::string model_path;  // the task's model, for the camera check
};

struct RenderOpenResult {
  std::unique_ptr<RenderSession> session;  // null on error
  std::string error;
  int exit_code = 0;
};

// Loads a module from the directory of the running binary. On failure returns null and sets
// `error` (the path and dlerror()).
void* OpenCommandModule(const std::string& file, std::string* error);
// The symbol `name` of a module opened above, or null with `error` set.
void* ModuleSymbol(void* module, const char* name, std::string* error);

struct PlotModule;
// librecruit-plot.so's entry points, the module opened on the first call; null with `error` set
// when it cannot be opened.
const PlotModule* OpenPlotModule(std::string* error);

}  // namespace recruit::cli

extern "C" {
// librecruit-plot.so: recruit::plot::RenderFigure (`bytes` on success, else `error`).
using RecruitPlotFigureFn = void (*)(const recruit::plot::Figure* figure, int width, int height,
                                     recruit::plot::Format format, std::string* bytes,
                                     recruit::Error* error);
// librecruit-render.so: checks the options and the camera and opens the outputs.
using RecruitRenderOpenFn = void (*)(const recruit::cli::RenderOpenRequest* request,
                                     recruit::cli::RenderOpenResult* result);
// librecruit-plot.so: recruit::plot::RunPlot.
using RecruitPlotRunFn = void (*)(const recruit::plot::PlotOptions* options,
                                  std::vector<std::string>* written, recruit::Error* error);
}

namespace recruit::cli {

struct PlotModule {
  RecruitPlotRunFn run = nullptr;
  RecruitPlotFigureFn figure = nullptr;
};

}  // namespace recruit::cli
