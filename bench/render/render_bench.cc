// Rendering throughput: render alone against render + encode, interleaved batch by batch in one
// run so the shared machine's noise hits both alike. Each iteration renders a batch of frames
// into memory (render_fps), then renders the same number again through the encoder pipeline
// into one MP4 that stays open for the whole run (pipeline_fps); ratio = pipeline_fps /
// render_fps. Arguments: width, height, encoder queue frames (0 = encode inline on the render
// thread), x264 preset (0 ultrafast, 1 veryfast, 2 medium), x264 threads (0 = automatic).
#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "render/encode_pipeline.h"
#include "render/scene_renderer.h"
#include "test_model.h"

namespace recruit::render {
namespace {

constexpr int kBatch = 30;  // frames per batch: 1 s of video at 30 frames/s
constexpr const char* kPresets[] = {"ultrafast", "veryfast", "medium"};

struct Scene {
  testing::ModelPtr m = testing::LoadXml(testing::kArmXml);
  testing::DataPtr d{mj_makeData(m.get())};
  double t = 0;
  // Moves the arm and the telemetry a frame's worth, so every frame differs (as in a run).
  TelemetrySample Advance() {
    const double target = t + 1.0 / 30;
    while (d->time < target) {
      d->ctrl[0] = 10 + 8 * std::sin(d->time);
      mj_step(m.get(), d.get());
    }
    t = d->time;
    const double u = 0.5 + 0.5 * std::sin(t);
    TelemetrySample s = testing::Sample(t, u, static_cast<int>(60 * u), 60 * u + std::cos(3 * t));
    s.reference = 15 + 5 * std::sin(0.5 * t);
    s.measured = 15 + 5 * std::sin(0.5 * t - 0.2);
    return s;
  }
};

double Seconds(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

// CPU time of the whole process (every thread: llvmpipe's, x264's, the encoder's), s.
double ProcessCpuSeconds() {
  rusage u;
  getrusage(RUSAGE_SELF, &u);
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

void BM_RenderVsRenderEncode(benchmark::State& state) {
  const int width = static_cast<int>(state.range(0));
  const int height = static_cast<int>(state.range(1));
  const int queue = static_cast<int>(state.range(2));
  H264Options h264;
  h264.preset = kPresets[state.range(3)];
  h264.threads = static_cast<int>(state.range(4));
  Scene scene;
  RenderOptions options;
  options.width = width;
  options.height = height;
  options.camera.name = "front";
  auto renderer =
      SceneRenderer::Create(scene.m.get(), options, RunLabel{"bench", "kalman", 0.5, 0.2, 1});
  if (!renderer.ok()) {
    state.SkipWithError(renderer.error().c_str());
    return;
  }
  std::vector<unsigned char> rgb(static_cast<size_t>(width) * height * 3);
  // One video for the whole run, as in a long render: the encoder's start-up and final flush are
  // paid once, outside the measured batches.
  const std::string path = "/tmp/recruit_render_bench_" + std::to_string(::getpid()) + ".mp4";
  auto mp4 = Mp4Writer::Open(path, width, height, 30, h264);
  if (!mp4.ok()) {
    state.SkipWithError(mp4.error().c_str());
    return;
  }
  EncodePipeline pipeline(width, height, std::move(*mp4), nullptr, 1, queue);
  double render_time = 0, pipeline_time = 0, render_cpu = 0, pipeline_cpu = 0;
  int64_t batches = 0, index = 0;
  for (auto _ : state) {
    // Render alone (the encoder is idle: the previous batch waited for it).
    const double c0 = ProcessCpuSeconds();
    auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < kBatch; ++i) {
      const TelemetrySample s = scene.Advance();
      (*renderer)->AddPlotPoint(s);
      if (!(*renderer)->Render(scene.m.get(), scene.d.get(), &s, rgb.data()).ok()) {
        state.SkipWithError("render failed");
        return;
      }
    }
    auto t1 = std::chrono::steady_clock::now();
    const double c1 = ProcessCpuSeconds();
    // Render + encode: the batch ends when the encoder has taken every frame of it.
    for (int i = 0; i < kBatch; ++i) {
      const TelemetrySample s = scene.Advance();
      auto frame = pipeline.Acquire();
      (*renderer)->AddPlotPoint(s);
      if (!frame.ok() ||
          !(*renderer)->Render(scene.m.get(), scene.d.get(), &s, (*frame)->rgb.data()).ok()) {
        state.SkipWithError("pipeline render failed");
        return;
      }
      (*frame)->index = index++;
      if (!pipeline.Submit(*frame).ok()) {
        state.SkipWithError("encode failed");
        return;
      }
    }
    pipeline.WaitIdle();
    auto t2 = std::chrono::steady_clock::now();
    const double c2 = ProcessCpuSeconds();
    render_time += Seconds(t0, t1);
    pipeline_time += Seconds(t1, t2);
    render_cpu += c1 - c0;
    pipeline_cpu += c2 - c1;
    ++batches;
  }
  if (Status s = pipeline.Finish(); !s.ok()) {
    state.SkipWithError(s.error().c_str());
    return;
  }
  size_t bytes = 0;
  if (FILE* f = std::fopen(path.c_str(), "rb")) {
    std::fseek(f, 0, SEEK_END);
    bytes = std::ftell(f);
    std::fclose(f);
  }
  std::remove(path.c_str());
  const double frames = static_cast<double>(batches) * kBatch;
  state.counters["render_fps"] = frames / render_time;
  state.counters["pipeline_fps"] = frames / pipeline_time;
  state.counters["ratio"] = render_time / pipeline_time;
  // CPU milliseconds per frame over all threads, and their ratio: what the pipeline keeps of the
  // render rate when both cores are saturated (a load-independent bound; see docs/benchmarks.md).
  state.counters["render_cpu_ms"] = 1e3 * render_cpu / frames;
  state.counters["pipeline_cpu_ms"] = 1e3 * pipeline_cpu / frames;
  state.counters["cpu_ratio"] = render_cpu / pipeline_cpu;
  state.counters["KB_per_s_video"] = bytes / 1024.0 / (frames / 30.0);
  state.SetLabel(std::string(kPresets[state.range(3)]) + (queue ? ", encoder thread" : ", inline"));
}

// Render alone with the model's 4x multisampling against none (arg msaa), frames per second.
void BM_RenderOnly(benchmark::State& state) {
  Scene scene;
  RenderOptions options;
  options.width = static_cast<int>(state.range(0));
  options.height = static_cast<int>(state.range(1));
  options.multisamples = static_cast<int>(state.range(2));
  options.camera.name = "front";
  auto renderer = SceneRenderer::Create(scene.m.get(), options, RunLabel{});
  if (!renderer.ok()) {
    state.SkipWithError(renderer.error().c_str());
    return;
  }
  std::vector<unsigned char> rgb(static_cast<size_t>(options.width) * options.height * 3);
  for (auto _ : state) {
    const TelemetrySample s = scene.Advance();
    (*renderer)->AddPlotPoint(s);
    benchmark::DoNotOptimize((*renderer)->Render(scene.m.get(), scene.d.get(), &s, rgb.data()));
  }
  state.counters["fps"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RenderOnly)
    ->ArgNames({"w", "h", "msaa"})
    ->Args({640, 480, 4})
    ->Args({640, 480, 0})
    ->Args({1280, 720, 4})
    ->Args({1280, 720, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// 640x480 and 1280x720; encoder thread (queue 4) against inline encoding (queue 0); x264's own
// threads (automatic) against one; three presets.
BENCHMARK(BM_RenderVsRenderEncode)
    ->ArgNames({"w", "h", "queue", "preset", "x264threads"})
    ->Args({640, 480, 4, 1, 0})
    ->Args({640, 480, 0, 1, 0})
    ->Args({640, 480, 4, 1, 1})
    ->Args({640, 480, 0, 1, 1})
    ->Args({640, 480, 4, 0, 0})
    ->Args({640, 480, 4, 2, 0})
    ->Args({1280, 720, 4, 1, 0})
    ->Args({1280, 720, 0, 1, 0})
    ->Args({1280, 720, 4, 1, 1})
    ->Args({1280, 720, 0, 1, 1})
    ->Unit(benchmark::kMillisecond);
// No MinTime here: a per-benchmark MinTime overrides --benchmark_min_time, so the command line
// could not shorten a run. The figures in docs/benchmarks.md were measured with 5 s per
// benchmark: pass --benchmark_min_time=5 to repeat them.

}  // namespace
}  // namespace recruit::render
