// librecruit-render.so: the part of `recruit render` that needs OpenGL and libav (see
// cli/command_modules.h). render_command.cc parses the options and runs the task; this checks
// the GL back end and the camera and creates the recorder.
#include <mujoco/mujoco.h>

#include <sstream>

#include "cli/command_modules.h"
#include "common/exit_codes.h"
#include "render/camera.h"
#include "render/gl_context.h"
#include "render/video_recorder.h"

namespace recruit::cli {
namespace {

class Session final : public RenderSession {
 public:
  Session(std::unique_ptr<render::VideoRecorder> rec, const render::VideoOptions& v)
      : rec_(std::move(rec)), v_(v) {}
  Status OnStep(const mjModel* m, const mjData* d, const TelemetrySample& s) override {
    return rec_->OnStep(m, d, s);
  }
  Status Finish() override { return rec_->Finish(); }
  std::string Report() const override {
    std::ostringstream out;
    out << rec_->frames_rendered() << " frames at " << v_.fps << " frames/s, " << v_.render.width
        << "x" << v_.render.height << " ("
        << (rec_->renderer() ? rec_->renderer()->gl_description() : "") << ")\n  wrote "
        << v_.mp4_path;
    if (!v_.gif_path.empty()) out << ", " << v_.gif_path;
    for (const std::string& still : rec_->stills_written()) out << ", " << still;
    return out.str();
  }

 private:
  std::unique_ptr<render::VideoRecorder> rec_;
  render::VideoOptions v_;
};

void Open(const RenderOpenRequest& req, RenderOpenResult* out) {
  render::VideoOptions v = req.video;
  auto backend =
      req.gl.empty() ? render::GlBackendFromEnvironment() : render::ParseGlBackend(req.gl);
  if (!backend.ok()) {
    out->error = "--gl: " + backend.error();
    out->exit_code = exit_code::kUsage;
    return;
  }
  v.render.backend = *backend;
  if (Status s = v.Validate(); !s.ok()) {
    out->error = s.error();
    out->exit_code = exit_code::kUsage;
    return;
  }
  // The camera against the task's model, before anything runs: a model that does not load is
  // bad input (3); a camera it does not have is a bad option (2).
  char error[1000] = "";
  mjModel* m = mj_loadXML(req.model_path.c_str(), nullptr, error, sizeof(error));
  if (!m) {
    out->error = "model '" + req.model_path + "': " + error;
    out->exit_code = exit_code::kBadInput;
    return;
  }
  auto cam = render::ResolveCamera(m, v.render.camera);
  mj_deleteModel(m);
  if (!cam.ok()) {
    out->error = "model '" + req.model_path + "': " + cam.error();
    out->exit_code = exit_code::kUsage;
    return;
  }
  auto recorder = render::VideoRecorder::Create(v);
  if (!recorder.ok()) {
    out->error = recorder.error();
    out->exit_code = exit_code::Of(recorder.code());
    return;
  }
  out->session = std::make_unique<Session>(std::move(*recorder), v);
}

}  // namespace
}  // namespace recruit::cli

extern "C" __attribute__((visibility("default"))) void recruit_render_open(
    const recruit::cli::RenderOpenRequest* request, recruit::cli::RenderOpenResult* result) {
  recruit::cli::Open(*request, result);
}
