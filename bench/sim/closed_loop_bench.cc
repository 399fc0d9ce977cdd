// Closed-loop speed: simulated seconds per wall second (the "x real time" counter), for the
// isometric bench and the elbow arm, output-only and filtered; plus the bare physics step of the
// same models (mj_step + plugin Advance, no controller) side by side as the reference.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <memory>

#include "plugin/sma_host.h"
#include "sim/run_task.h"
#include "sim/task.h"

namespace recruit::sim {
namespace {

const std::string kRoot = RECRUIT_SOURCE_DIR;

void RunClosedLoop(benchmark::State& state, const std::string& task_file,
                   const std::string& estimator, double dT, double duration) {
  auto task = Task::FromFile(kRoot + "/" + task_file);
  if (!task.ok()) {
    state.SkipWithError(task.error().c_str());
    return;
  }
  RunOptions o;
  o.estimator = estimator;
  o.dT = dT;
  o.duration = duration;
  // RECRUIT_FILTER_MODEL overrides the filter model (default: models/identified/ for dT).
  if (const char* fm = std::getenv("RECRUIT_FILTER_MODEL"); fm && estimator != "output") {
    o.filter_model = fm;
  }
  double simulated = 0;
  for (auto _ : state) {
    auto r = RunTask(*task, o);
    if (!r.ok()) {
      state.SkipWithError(r.error().c_str());
      return;
    }
    simulated += r->duration;
    ++o.seed;
  }
  state.counters["x_real_time"] = benchmark::Counter(simulated, benchmark::Counter::kIsRate);
}

void BM_BenchOutput_dT2(benchmark::State& s) {
  RunClosedLoop(s, "models/tasks/isometric_paper.json", "output", 2.0, 200);
}
void BM_BenchOutput_dT05(benchmark::State& s) {
  RunClosedLoop(s, "models/tasks/isometric_paper.json", "output", 0.5, 200);
}
void BM_BenchKalman_dT05(benchmark::State& s) {
  RunClosedLoop(s, "models/tasks/isometric_paper.json", "kalman-augmented", 0.5, 200);
}
void BM_ArmOutput_dT1(benchmark::State& s) {
  RunClosedLoop(s, "models/tasks/arm_reach_hold.json", "output", 1.0, 110);
}
void BM_ArmKalman_dT05(benchmark::State& s) {
  RunClosedLoop(s, "models/tasks/arm_reach_hold.json", "kalman-augmented", 0.5, 110);
}

// Physics alone: mj_step + Advance with half the units switched on once, for 20 s.
void PhysicsOnly(benchmark::State& state, const std::string& model_file) {
  char err[1000];
  mjModel* m = mj_loadXML((kRoot + "/" + model_file).c_str(), nullptr, err, sizeof err);
  if (!m) {
    state.SkipWithError(err);
    return;
  }
  auto plugin = sma::SmaHost::Create(m);
  mjData* d = mj_makeData(m);
  double simulated = 0;
  for (auto _ : state) {
    mj_resetData(m, d);
    (*plugin)->Reset(d, 1);
    for (int b = 0; b < (*plugin)->num_bundles(); ++b) (void)(*plugin)->Broadcast(d, b, 0.5, 0);
    const long n = std::lround(20.0 / m->opt.timestep);
    for (long i = 0; i < n; ++i) mj_step(m, d);
    simulated += d->time;
  }
  state.counters["x_real_time"] = benchmark::Counter(simulated, benchmark::Counter::kIsRate);
  mj_deleteData(d);
  plugin->reset();
  mj_deleteModel(m);
}
void BM_PhysicsOnly_Bench(benchmark::State& s) { PhysicsOnly(s, "models/isometric_bench.xml"); }
void BM_PhysicsOnly_Arm(benchmark::State& s) { PhysicsOnly(s, "models/elbow_arm.xml"); }

// The reference under the arm's figures: the same arm with MuJoCo's built-in muscles (no plugin),
// half activated, for 20 s: MuJoCo's own step of this model.
void BM_PhysicsOnly_ArmMuscle(benchmark::State& state) {
  char err[1000];
  mjModel* m =
      mj_loadXML((kRoot + "/models/elbow_arm_muscle.xml").c_str(), nullptr, err, sizeof err);
  if (!m) {
    state.SkipWithError(err);
    return;
  }
  mjData* d = mj_makeData(m);
  double simulated = 0;
  for (auto _ : state) {
    mj_resetData(m, d);
    for (int i = 0; i < m->nu; ++i) d->ctrl[i] = 0.5;
    const long n = std::lround(20.0 / m->opt.timestep);
    for (long i = 0; i < n; ++i) mj_step(m, d);
    simulated += d->time;
  }
  state.counters["x_real_time"] = benchmark::Counter(simulated, benchmark::Counter::kIsRate);
  mj_deleteData(d);
  mj_deleteModel(m);
}

BENCHMARK(BM_PhysicsOnly_Bench)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BenchOutput_dT2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BenchOutput_dT05)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BenchKalman_dT05)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PhysicsOnly_Arm)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PhysicsOnly_ArmMuscle)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ArmOutput_dT1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ArmKalman_dT05)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace recruit::sim
