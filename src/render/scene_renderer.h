// SceneRenderer: draws one frame of a running task off-screen with MuJoCo's renderer: a title
// line (task, estimator, dT, lambda, time), the scene from the chosen camera with each bundle's
// tendon coloured by its heat, labelled with its name and temperature, a key of the heat
// colours, and the scrolling TelemetryPlots (or, without them, a panel of counts and heat). It owns
// its GL context (GlContext), mjvScene and mjrContext; frames come back as packed RGB rows,
// bottom-up as GL reads them.
#pragma once

#include <mujoco/mujoco.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "common/result.h"
#include "common/telemetry.h"
#include "render/camera.h"
#include "render/gl_context.h"
#include "render/telemetry_plots.h"
#include "render/unit_counts.h"

namespace recruit::render {

// MuJoCo font scale (mjtFontScale, %) for a frame: 100 at 560 x 400, proportional to the
// smaller of width / 560 and height / 400, in 50 % steps from 50 to 300.
int FontScaleFor(int width, int height);

struct RunLabel;
// "task   estimator E   dT X s   lambda Y   t Z s": the frame's title line.
std::string TitleLine(const RunLabel& label, double time);

// Constant facts about the run, shown in the title line.
struct RunLabel {
  std::string task;       // task name or file
  std::string estimator;  // e.g. "kalman", "none"
  double dT = 0;          // s, controller sampling period
  double lambda = 0;      // expectation-law gain
  uint64_t seed = 0;
};

struct RenderOptions {
  int width = 640;   // pixels
  int height = 480;  // pixels
  CameraSpec camera;
  GlBackend backend = GlBackend::kOsMesa;
  bool figures = true;  // the scrolling plots (TelemetryPlots)
  // The title line (task, estimator, dT, lambda, time); without plots also the mjr_overlay
  // panel of counts and heat over the scene.
  bool text_panel = true;
  bool labels = true;         // each bundle's name and temperature next to its tendon
  bool heat_key = true;       // the key of the tendon heat colours
  bool heat_colours = true;   // colour each bundle's tendon by its heat
  double figure_window = 20;  // s of history in the plots
  // Draw each bundle's tendon at least this thick (m, radius); 0 = as the model says. 3.5 mm
  // is about 4 px across in a whole-arm shot at 640 x 480. Real SMA
  // bundles are a few mm thick, a pixel or two in a whole-arm shot.
  double min_tendon_width = 0.0035;
  // Draw every geom but planes at 35 % opacity (tendons stay opaque), so tendons routed inside
  // a bone's capsule show through it. MuJoCo's own mjVIS_TRANSPARENT only affects moving bodies.
  bool transparent = false;
  int multisamples = -1;  // offscreen MSAA samples; -1 = the model's <quality offsamples>

  static constexpr int kMinSide = 16;
  static constexpr int kMaxSide = 8192;
  // Checks what can be checked without a model or GL (sizes, window).
  Status Validate() const;
};

class SceneRenderer {
 public:
  // Creates the GL context, checks the camera against the model and the size against the
  // driver, and builds MuJoCo's rendering context. The model's offscreen buffer
  // (<visual><global offwidth offheight>) is enlarged on a private copy when the frame is
  // larger, so a model needs no edit to render at any size the driver supports.
  static Result<std::unique_ptr<SceneRenderer>> Create(const mjModel* m,
                                                       const RenderOptions& options,
                                                       const RunLabel& label);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  // Adds the sample to the scrolling plots (the recorder calls it once per frame).
  void AddPlotPoint(const TelemetrySample& sample);
  // The same with the bundles' unit counts read from `d` (render/unit_counts.h).
  void AddPlotPoint(const mjModel* m, const mjData* d, const TelemetrySample& sample);

  // Renders the state in `d` into `rgb` (width * height * 3 bytes, rows bottom-up). `sample`
  // may be null (no heat colours, no panel values). `d` is read only; mjv_updateScene's
  // signature takes a non-const mjData, hence the cast inside.
  Status Render(const mjModel* m, const mjData* d, const TelemetrySample* sample,
                unsigned char* rgb);

  int width() const { return options_.width; }
  int height() const { return options_.height; }
  const std::string& gl_description() const { return gl_description_; }
  // Geoms recoloured in the last frame (tests check the tendon was found).
  int last_recoloured_geoms() const { return last_recoloured_; }

 private:
  SceneRenderer(const RenderOptions& options, const RunLabel& label);
  void DrawPanel(const TelemetrySample* sample, mjrRect viewport,
                 const std::vector<std::optional<UnitCounts>>& counts);

  RenderOptions options_;
  RunLabel label_;
  std::unique_ptr<GlContext> gl_;
  std::string gl_description_;
  mjvScene scene_;
  mjvOption option_;
  mjvCamera camera_;
  mjvPerturb perturb_;
  mjrContext context_;
  bool scene_made_ = false;
  bool context_made_ = false;
  std::unique_ptr<TelemetryPlots> plots_;
  UnitCountReader counts_;  // failing bundles' working/open/stuck units
  int last_recoloured_ = 0;
};

}  // namespace recruit::render
