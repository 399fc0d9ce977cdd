// librecruit-plot.so: `recruit plot`'s drawing (cairo), opened only when it runs (see
// cli/command_modules.h).
#include <string>
#include <vector>

// No MuJoCo here: the signatures are RecruitPlotRunFn and RecruitPlotFigureFn of
// cli/command_modules.h.
#include "plot/plot_run.h"
#include "plot/render.h"

extern "C" __attribute__((visibility("default"))) void recruit_plot_run(
    const recruit::plot::PlotOptions* options, std::vector<std::string>* written,
    recruit::Error* error) {
  auto r = recruit::plot::RunPlot(*options);
  if (r.ok()) {
    *written = std::move(*r);
  } else {
    *error = r.failure();
  }
}

extern "C" __attribute__((visibility("default"))) void recruit_plot_figure(
    const recruit::plot::Figure* figure, int width, int height, recruit::plot::Format format,
    std::string* bytes, recruit::Error* error) {
  auto r = recruit::plot::RenderFigure(*figure, width, height, format);
  if (r.ok()) {
    *bytes = std::move(*r);
  } else {
    *error = r.failure();
  }
}
