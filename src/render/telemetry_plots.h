// TelemetryPlots: two scrolling MuJoCo figures drawn beside the scene, (1) the tracked quantity
// against its reference (force in N, or the joint angle in deg) and (2) each bundle's true
// against estimated on-count. mjvFigure is about 800 KB (100 lines x 1000 points), so both live
// on the heap.
#pragma once

#include <mujoco/mujoco.h>

#include <memory>

#include "common/telemetry.h"

namespace recruit::render {

class TelemetryPlots {
 public:
  // `window` is the time span shown, s (> 0): older points scroll out on the left.
  explicit TelemetryPlots(double window);

  // Appends one point per line at sample.time. Non-finite values (an estimate when no estimator
  // runs) are left out of their line.
  void Add(const TelemetrySample& sample);

  // Draws both figures, stacked, into `area` (pixels). Call between mjr_render and
  // mjr_readPixels.
  void Draw(mjrRect area, const mjrContext* con);

  const mjvFigure& tracking() const { return *tracking_; }
  const mjvFigure& recruitment() const { return *recruitment_; }

  static constexpr int kMaxBundles = 4;  // bundles drawn in the recruitment figure

 private:
  void Push(mjvFigure* fig, int line, double x, double y);
  void Scroll(mjvFigure* fig, double now);

  double window_;
  bool configured_ = false;
  bool angle_ = false;  // the tracked quantity is a joint angle (plotted in deg)
  std::unique_ptr<mjvFigure> tracking_;
  std::unique_ptr<mjvFigure> recruitment_;
};

}  // namespace recruit::render
