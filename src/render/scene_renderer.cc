#include "render/scene_renderer.h"

#include <cmath>
#include <cstdio>

#include "render/scene_labels.h"
#include "render/tendon_heat.h"

namespace recruit::render {
namespace {

std::string Size(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

// 0.12 -> ".12", 1 -> "1.00": the panel column is narrow.
std::string Fraction(double x) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.2f", x);
  return buf[0] == '0' && buf[1] == '.' ? std::string(buf + 1) : std::string(buf);
}

struct ModelCopy {
  mjModel* m = nullptr;
  ~ModelCopy() {
    if (m) mj_deleteModel(m);
  }
};

}  // namespace

int FontScaleFor(int width, int height) {
  // 100 % at 560 x 400 (640 x 360 .. 640 x 480 get 100 %), in MuJoCo's 50 % steps from 50 % to
  // 300 %: text stays about 1/20 of the frame height, readable when a 720p frame is shown at
  // 880 px or a 640 x 360 GIF at its size.
  const double s = 100.0 * std::min(width / 560.0, height / 400.0);
  const int steps = static_cast<int>(std::floor(s / 50.0 + 0.25));
  return std::clamp(steps, 1, 6) * 50;
}

std::string TitleLine(const RunLabel& label, double time) {
  char buf[256];
  std::snprintf(buf, sizeof(buf), "%s   estimator %s   dT %.3g s   lambda %.3g   t %.1f s",
                label.task.empty() ? "run" : label.task.c_str(),
                label.estimator.empty() ? "none" : label.estimator.c_str(), label.dT, label.lambda,
                time);
  return buf;
}

Status RenderOptions::Validate() const {
  if (width < kMinSide || height < kMinSide || width > kMaxSide || height > kMaxSide) {
    return Error{"frame size " + Size(width, height) +
                 " is out of range: width and height must be "
                 "in [" +
                 std::to_string(kMinSide) + ", " + std::to_string(kMaxSide) + "] pixels"};
  }
  if (!(figure_window > 0) || !std::isfinite(figure_window)) {
    return Error{"figure window must be a positive number of seconds"};
  }
  if (!std::isfinite(min_tendon_width) || min_tendon_width < 0 || min_tendon_width > 1) {
    return Error{"minimum tendon width must be in [0, 1] m (0 = the model's), got " +
                 std::to_string(min_tendon_width)};
  }
  if (multisamples != -1 && (multisamples < 0 || multisamples > 16)) {
    return Error{"multisamples must be -1 (the model's value) or in [0, 16], got " +
                 std::to_string(multisamples)};
  }
  return Status::Ok();
}

SceneRenderer::SceneRenderer(const RenderOptions& options, const RunLabel& label)
    : options_(options), label_(label) {
  mjv_defaultScene(&scene_);
  mjv_defaultOption(&option_);
  mjv_defaultCamera(&camera_);
  mjv_defaultPerturb(&perturb_);
  mjr_defaultContext(&context_);
}

SceneRenderer::~SceneRenderer() {
  if (gl_) (void)gl_->MakeCurrent();
  if (context_made_) mjr_freeContext(&context_);
  if (scene_made_) mjv_freeScene(&scene_);
}

Result<std::unique_ptr<SceneRenderer>> SceneRenderer::Create(const mjModel* m,
                                                             const RenderOptions& options,
                                                             const RunLabel& label) {
  if (!m) return Error{"render: no model"};
  if (Status s = options.Validate(); !s.ok()) return Error{s.error(), s.code()};
  auto camera = ResolveCamera(m, options.camera);
  if (!camera.ok()) return Error{camera.error(), camera.code()};

  std::unique_ptr<SceneRenderer> r(new SceneRenderer(options, label));
  r->camera_ = *camera;
  auto gl = GlContext::Create(options.backend, options.width, options.height);
  if (!gl.ok()) return Error{gl.error(), gl.code()};
  r->gl_ = std::move(*gl);
  r->gl_description_ = r->gl_->Description();
  const int max_side = r->gl_->MaxRenderbufferSize();
  if (max_side > 0 && (options.width > max_side || options.height > max_side)) {
    return Error{"frame size " + Size(options.width, options.height) +
                 " exceeds this GL driver's largest offscreen buffer side, " +
                 std::to_string(max_side) + " pixels (" + r->gl_description_ + ")"};
  }

  // A private copy whose offscreen buffer fits the frame: mjr_makeContext sizes the buffer from
  // <visual><global offwidth offheight> (default 640x480).
  ModelCopy copy;
  copy.m = mj_copyModel(nullptr, m);
  if (!copy.m) return Error{"render: could not copy the model"};
  copy.m->vis.global.offwidth = std::max(copy.m->vis.global.offwidth, options.width);
  copy.m->vis.global.offheight = std::max(copy.m->vis.global.offheight, options.height);
  if (options.multisamples >= 0) copy.m->vis.quality.offsamples = options.multisamples;

  mjv_makeScene(m, &r->scene_, 2000);
  r->scene_made_ = true;
  mjr_makeContext(copy.m, &r->context_, FontScaleFor(options.width, options.height));
  r->context_made_ = true;
  if (r->context_.offWidth < options.width || r->context_.offHeight < options.height) {
    return Error{"render: MuJoCo made a " + Size(r->context_.offWidth, r->context_.offHeight) +
                 " offscreen buffer, smaller than the " + Size(options.width, options.height) +
                 " frame"};
  }
  mjr_setBuffer(mjFB_OFFSCREEN, &r->context_);
  if (r->context_.currentBuffer != mjFB_OFFSCREEN) {
    return Error{"render: the offscreen framebuffer is not supported by " + r->gl_description_};
  }
  if (options.figures) r->plots_ = std::make_unique<TelemetryPlots>(options.figure_window);
  return r;
}

void SceneRenderer::AddPlotPoint(const TelemetrySample& sample) {
  if (plots_) plots_->Add(sample);
}

void SceneRenderer::AddPlotPoint(const mjModel* m, const mjData* d, const TelemetrySample& sample) {
  if (plots_) plots_->Add(sample, counts_.Read(m, d, sample));
}

void SceneRenderer::DrawPanel(const TelemetrySample* s, mjrRect viewport,
                              const std::vector<std::optional<UnitCounts>>& counts) {
  std::string titles, values;
  auto row = [&](const std::string& title, const std::string& value) {
    if (!titles.empty()) {
      titles += "\n";
      values += "\n";
    }
    titles += title;
    values += value;
  };
  char buf[160];
  if (s) {
    if (s->reference_unit == "rad") {
      std::snprintf(buf, sizeof(buf), "%.1f deg (ref %.1f)", s->measured * 180 / M_PI,
                    s->reference * 180 / M_PI);
      row("angle", buf);
    } else {
      std::snprintf(buf, sizeof(buf), "%.3g %s (ref %.3g)", s->measured, s->reference_unit.c_str(),
                    s->reference);
      row("force", buf);
    }
    for (size_t i = 0; i < s->bundles.size(); ++i) {
      const BundleTelemetry& b = s->bundles[i];
      if (std::isfinite(b.estimated_on)) {
        std::snprintf(buf, sizeof(buf), "%d on, est %.1f, heat %s", b.true_on, b.estimated_on,
                      Fraction(b.heat).c_str());
      } else {
        std::snprintf(buf, sizeof(buf), "%d on, heat %s", b.true_on, Fraction(b.heat).c_str());
      }
      std::string value = buf;
      if (i < counts.size() && counts[i]) {
        value += ", " + std::to_string(counts[i]->working) + "/" +
                 std::to_string(counts[i]->total()) + " working";
      }
      row(b.actuator, value);
    }
  }
  if (titles.empty()) return;
  mjr_overlay(mjFONT_NORMAL, mjGRID_BOTTOMRIGHT, viewport, titles.c_str(), values.c_str(),
              &context_);
}

Status SceneRenderer::Render(const mjModel* m, const mjData* d, const TelemetrySample* sample,
                             unsigned char* rgb) {
  if (Status s = gl_->MakeCurrent(); !s.ok()) return s;
  // mjv_updateScene only reads d; its C signature is not const-correct.
  mjv_updateScene(m, const_cast<mjData*>(d), &option_, &perturb_, &camera_, mjCAT_ALL, &scene_);
  last_recoloured_ = 0;
  if (sample && options_.heat_colours) {
    last_recoloured_ = ColourTendonsByHeat(m, *sample, &scene_);
  }
  if (options_.transparent) {
    // Every geom but planes (the floor) at 35 % opacity; tendons stay opaque.
    for (int g = 0; g < scene_.ngeom; ++g) {
      mjvGeom& geom = scene_.geoms[g];
      if (geom.objtype == mjOBJ_GEOM && geom.type != mjGEOM_PLANE) geom.rgba[3] *= 0.35f;
    }
  }
  if (sample && options_.min_tendon_width > 0) {
    WidenTendons(m, *sample, options_.min_tendon_width, &scene_);
  }
  mjr_setBuffer(mjFB_OFFSCREEN, &context_);
  const mjrRect viewport = {0, 0, options_.width, options_.height};
  const int ch = context_.charHeight;
  // Top: the title line (task, estimator, dT, lambda, time) across the frame. Below it, with
  // plots, the scene takes the left 55 % and the plots the right 45 %, so nothing covers the
  // model.
  const int title_h = options_.text_panel ? ch + ch / 2 : 0;
  const int below = options_.height - title_h;
  const int side = plots_ ? options_.width * 9 / 20 : 0;
  const mjrRect scene_viewport = {0, 0, options_.width - side, below};
  mjr_render(scene_viewport, &scene_, &context_);
  // Each bundle's working/open/stuck units, when its units can fail (none otherwise).
  const std::vector<std::optional<UnitCounts>> counts =
      sample ? counts_.Read(m, d, *sample) : std::vector<std::optional<UnitCounts>>{};
  if (sample && options_.labels) {
    DrawTendonLabels(PlaceTendonLabels(m, d, scene_, scene_viewport, *sample, counts),
                     scene_viewport, &context_);
  }
  if (sample && options_.heat_colours && options_.heat_key) {
    // Bottom left, over the floor: the arm and its reach stay clear.
    const std::vector<std::string> rows = HeatKeyRows(*sample, counts);
    DrawHeatKey(ch / 2, ch / 2 + HeatKeyHeight(&context_, static_cast<int>(rows.size())), 0,
                &context_, rows);
  }
  if (options_.text_panel) {
    const mjrRect strip = {0, below, options_.width, title_h};
    mjr_rectangle(strip, 0.08f, 0.08f, 0.1f, 1.f);
    const std::string title = TitleLine(label_, sample ? sample->time : 0.0);
    mjr_label({ch / 2, below, TextWidth(title, &context_), title_h}, mjFONT_NORMAL, title.c_str(),
              0, 0, 0, 0, 1, 1, 1, &context_);
  }
  if (plots_) {
    const mjrRect column = {options_.width - side, 0, side, below};
    mjr_rectangle(column, 0.05f, 0.05f, 0.08f, 1.f);
    plots_->Draw(column, &context_);
  } else if (options_.text_panel) {
    DrawPanel(sample, scene_viewport, counts);
  }
  mjr_readPixels(rgb, nullptr, viewport, &context_);
  if (const int err = mjr_getError(); err != 0) {
    char code[16];
    std::snprintf(code, sizeof(code), "0x%04X", static_cast<unsigned>(err));
    return Error{std::string("render: OpenGL error ") + code + " while drawing the frame"};
  }
  return Status::Ok();
}

}  // namespace recruit::render
