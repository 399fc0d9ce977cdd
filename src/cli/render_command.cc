// recruit render --task FILE: runs the task once in closed loop and films it while it runs (the
// VideoRecorder is one of RunTask's step observers): H.264 MP4, optionally a GIF and PNG stills.
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

#include "cli/command_modules.h"
#include "cli/commands.h"
#include "cli/errors.h"
#include "cli/run_options.h"
#include "common/output_path.h"
#include "sim/run_task.h"

namespace recruit::cli {
namespace {

struct RenderArgs {
  std::string task;
  sim::RunOptions run;
  render::VideoOptions video;
  std::string out = "render.mp4";
  std::string camera;
  std::optional<double> azimuth, elevation, distance;
  std::vector<double> lookat;
  std::string gl;
  bool no_figures = false, no_panel = false;
  std::string stills_prefix;
};

int Run(RenderArgs& a) {
  auto task = sim::Task::FromFile(a.task);
  if (!task.ok()) {
    return Fail("render", task.failure());
  }
  render::VideoOptions& v = a.video;
  v.mp4_path = a.out;
  render::CameraSpec& cam = v.render.camera;
  cam.name = a.camera;
  cam.azimuth = a.azimuth;
  cam.elevation = a.elevation;
  cam.distance = a.distance;
  if (!a.lookat.empty()) cam.lookat = std::array<double, 3>{a.lookat[0], a.lookat[1], a.lookat[2]};
  v.render.figures = !a.no_figures;
  v.render.text_panel = !a.no_panel;
  if (v.still_every > 0 || !v.still_times.empty()) {
    v.still_prefix = a.stills_prefix;
    if (v.still_prefix.empty()) {
      const std::filesystem::path out(a.out);
      v.still_prefix = (out.parent_path() / out.stem()).string() + "_";
    }
  }
  const sim::ControllerSettings settings = sim::EffectiveSettings(*task, a.run);
  // Outputs never replace inputs (the task, its model, the filter model).
  const std::vector<std::pair<std::string, std::string>> inputs = {
      {"--task", a.task},
      {"the task's model", task->model_path},
      {"the filter model", settings.filter_model}};
  for (const auto& [label, path] :
       {std::pair{"--out", v.mp4_path}, std::pair{"--gif", v.gif_path}}) {
    if (path.empty()) continue;
    if (Status s = CheckNotAnInput(path, label, inputs); !s.ok()) {
      return Fail("render", s.error(), exit_code::kUsage);
    }
  }
  v.label.task = task->name;
  v.label.estimator = settings.estimator;
  v.label.dT = settings.dT;
  v.label.lambda = settings.lambda;
  v.label.seed = a.run.seed;

  // Stills are taken from frames; none is rendered after the run's end.
  const double duration = a.run.duration ? *a.run.duration : task->duration;
  for (double t : v.still_times) {
    if (t > duration + 1e-9) {
      char msg[200];
      std::snprintf(msg, sizeof(msg),
                    "--stills: %g s is after the run's end (%g s); stills must be in [0, %g] s", t,
                    duration, duration);
      return Fail("render", msg, exit_code::kUsage);
    }
  }
  // The rendering code (OSMesa, libav) is loaded only now (cli/command_modules.h).
  std::string error;
  void* module = OpenCommandModule("librecruit-render.so", &error);
  auto open = module ? reinterpret_cast<RecruitRenderOpenFn>(
                           ModuleSymbol(module, "recruit_render_open", &error))
                     : nullptr;
  if (!open) return Fail("render", error, exit_code::kIo);
  RenderOpenRequest request{v, a.gl, task->model_path};
  RenderOpenResult opened;
  open(&request, &opened);
  if (!opened.session) return Fail("render", opened.error, opened.exit_code);
  RenderSession& session = *opened.session;
  sim::RunOptions run = a.run;
  run.progress = run.progress || ::isatty(STDERR_FILENO);
  auto result = sim::RunTask(*task, run, {&session});
  if (!result.ok()) {
    return Fail("render", result.failure());
  }
  if (Status s = session.Finish(); !s.ok()) {
    return Fail("render", s.failure());
  }
  std::cout << "task " << result->task << ", seed " << result->seed << ": " << session.Report()
            << "\n  " << result->duration << " s simulated and rendered in " << result->wall_seconds
            << " s\n";
  return exit_code::kOk;
}

}  // namespace

void AddRenderCommand(CLI::App& app, int& exit_code) {
  auto a = std::make_shared<RenderArgs>();
  auto* cmd = app.add_subcommand(
      "render",
      "Run one task in closed loop and film it while it runs (MuJoCo's renderer, headless): "
      "an H.264 MP4 with force and on-count plots, a text panel and tendons coloured by heat; "
      "optionally a GIF and PNG stills");
  cmd->add_option("--task", a->task, "Task file (JSON, docs/formats/task.md)")
      ->required()
      ->check(CLI::ExistingFile);
  AddRunOptions(cmd, &a->run);
  cmd->add_option("--out", a->out, "Video file (.mp4, H.264 yuv420p, faststart)")
      ->capture_default_str();
  cmd->add_option("--fps", a->video.fps, "Frame rate, frames/s of simulated time, in [1, 240]")
      ->capture_default_str();
  cmd->add_option("--width", a->video.render.width, "Frame width, pixels (even)")
      ->capture_default_str();
  cmd->add_option("--height", a->video.render.height, "Frame height, pixels (even)")
      ->capture_default_str();
  auto* camera = cmd->add_option("--camera", a->camera,
                                 "A camera the model names [default: the model's camera \"render\" "
                                 "if any, else the free camera]");
  auto* az = cmd->add_option("--azimuth", a->azimuth, "Free camera azimuth, deg");
  auto* el = cmd->add_option("--elevation", a->elevation, "Free camera elevation, deg, [-90, 90]");
  auto* di = cmd->add_option("--distance", a->distance, "Free camera distance, m (> 0)");
  auto* la = cmd->add_option("--lookat", a->lookat, "Free camera look-at point X,Y,Z, m")
                 ->expected(3)
                 ->delimiter(',');
  for (auto* o : {az, el, di, la}) camera->excludes(o);
  cmd->add_option("--gif", a->video.gif_path, "Also write an animated GIF here (.gif)");
  cmd->add_option("--gif-fps", a->video.gif_fps, "GIF frame rate, <= --fps")->capture_default_str();
  cmd->add_option("--gif-width", a->video.gif_width, "GIF width, pixels")->capture_default_str();
  cmd->add_option("--still-every", a->video.still_every, "Write a PNG still every SECONDS")
      ->type_name("SECONDS");
  cmd->add_option("--stills", a->video.still_times, "PNG stills at these times, s (T1,T2,...)")
      ->delimiter(',');
  cmd->add_option("--stills-prefix", a->stills_prefix,
                  "Stills are PREFIXt<time>.png [default: the --out path without .mp4, then _]");
  cmd->add_option("--preset", a->video.h264.preset,
                  "x264 preset: ultrafast .. veryslow (speed against file size)")
      ->capture_default_str();
  cmd->add_option("--crf", a->video.h264.crf, "x264 constant rate factor, 0..51 (lower = better)")
      ->capture_default_str();
  cmd->add_option("--encoder-threads", a->video.h264.threads,
                  "x264 threads (0 = 1.5 per core: the video then depends on the machine)")
      ->capture_default_str();
  cmd->add_option("--gl", a->gl,
                  "OpenGL back end: osmesa (software, no display) or egl (GPU driver) "
                  "[default: $RECRUIT_GL, else $MUJOCO_GL, else osmesa]");
  cmd->add_option("--msaa", a->video.render.multisamples,
                  "Offscreen multisamples, 0..16 (-1 = the model's <quality offsamples>)")
      ->capture_default_str();
  cmd->add_option("--figure-window", a->video.render.figure_window, "Seconds shown in the plots")
      ->capture_default_str();
  cmd->add_option("--tendon-width", a->video.render.min_tendon_width,
                  "Draw bundle tendons at least this thick (radius, m; 0 = the model's width)")
      ->capture_default_str();
  cmd->add_flag(
      "--transparent", a->video.render.transparent,
      "Draw bodies translucent (35 % opacity, floor and tendons opaque) so tendons inside "
      "bones show");
  cmd->add_flag("--no-figures", a->no_figures, "Leave out the two plots");
  cmd->add_flag("--no-panel", a->no_panel, "Leave out the text panel");
  cmd->callback([a, &exit_code] { exit_code = Run(*a); });
}

}  // namespace recruit::cli
