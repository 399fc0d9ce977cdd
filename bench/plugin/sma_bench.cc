// Cost of the SMA plugin per physics step.
//  - Isometric bench, 60 units, against the same bench with one built-in <muscle> on the same
//    tendon (models/isometric_bench_muscle.xml); BM_SmaOverMuscle interleaves the two in blocks
//    of 1000 steps and reports their time ratio, which a shared, noisy machine cannot skew.
//  - Cost as the bundle grows (60, 600, 6000 units) in two regimes: the Fig. 4 step (all units
//    switch together, on for 10 s then off for 6 s) and busy random switching (p_on = p_off =
//    0.1 every 0.5 s, so most units are in a transient with their own history).
#include <benchmark/benchmark.h>
#include <time.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "plugin/sma_host.h"

namespace {

using recruit::sma::SmaHost;

mjModel* Load(const std::string& path) {
  char err[1000] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, err, sizeof err);
  if (m == nullptr) std::fprintf(stderr, "%s: %s\n", path.c_str(), err);
  return m;
}

// The models' folder: RECRUIT_BENCH_MODELS when set (e.g. another checkout's models/, to
// measure this plugin on its benches), else this source tree's models/.
std::string ModelPath(const char* file) {
  const char* dir = std::getenv("RECRUIT_BENCH_MODELS");
  return std::string(dir != nullptr && dir[0] != '\0' ? dir : RECRUIT_SOURCE_DIR "/models") + "/" +
         file;
}

// The bench with `units` units and the update period; without `truth`, minus the plugin's
// ground-truth sensor (the muscle bench has none: like for like); bins > 0: unit_model=binned
// with that many bins (plugin/README.md "Unit models"), else the exact model.
std::string BenchWithUnits(int units, int update_ms, bool truth = true, int bins = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "/tmp/recruit_sma_bench_%d_%d%s_%d.xml", units, update_ms,
                truth ? "" : "_notruth", bins);
  std::FILE* in = std::fopen(ModelPath("isometric_bench.xml").c_str(), "r");
  std::string xml;
  char chunk[4096];
  size_t n;
  while ((n = std::fread(chunk, 1, sizeof chunk, in)) > 0) xml.append(chunk, n);
  std::fclose(in);
  auto replace = [&](const std::string& from, const std::string& to) {
    xml.replace(xml.find(from), from.size(), to);
  };
  replace("<config key=\"units\" value=\"60\"/>", "<config key=\"units\" value=\"" +
                                                      std::to_string(units) +
                                                      "\"/><config key=\"update_period\" value=\"" +
                                                      std::to_string(update_ms * 1e-3) + "\"/>" +
                                                      (bins > 0 ? "<config key=\"unit_model\" "
                                                                  "value=\"binned\"/><config "
                                                                  "key=\"bins\" value=\"" +
                                                                      std::to_string(bins) + "\"/>"
                                                                : std::string()));
  if (!truth) replace("<plugin name=\"bundle_truth\" instance=\"bundle_units\"/>", "");
  std::FILE* out = std::fopen(buf, "w");
  std::fwrite(xml.data(), 1, xml.size(), out);
  std::fclose(out);
  return buf;
}

enum class Regime { kFig4Step, kRandomSwitching };

// One simulated second of the regime's broadcasts at step i (1 ms steps).
void Control(const SmaHost& p, mjData* d, Regime regime, long i) {
  if (regime == Regime::kFig4Step) {
    if (i % 16000 == 0) (void)p.Broadcast(d, 0, 1, 0);
    if (i % 16000 == 10000) (void)p.Broadcast(d, 0, 0, 1);
  } else if (i % 500 == 0) {
    (void)p.Broadcast(d, 0, 0.1, 0.1);
  }
}

void BM_MuscleBaseline(benchmark::State& state) {
  mjModel* m = Load(ModelPath("isometric_bench_muscle.xml"));
  mjData* d = mj_makeData(m);
  d->ctrl[0] = 1;
  for (auto _ : state) mj_step(m, d);
  state.SetItemsProcessed(state.iterations());
  mj_deleteData(d);
  mj_deleteModel(m);
}
BENCHMARK(BM_MuscleBaseline)->Iterations(48000);  // fixed: callgrind counts per step

void BM_Sma(benchmark::State& state) {
  const int units = static_cast<int>(state.range(0));
  const auto regime = static_cast<Regime>(state.range(1));
  const int update_ms = static_cast<int>(state.range(2));
  mjModel* m = Load(BenchWithUnits(units, update_ms));
  auto p = SmaHost::Create(m);
  if (!p.ok()) {
    state.SkipWithError(p.error().c_str());
    mj_deleteModel(m);
    return;
  }
  mjData* d = mj_makeData(m);
  (*p)->Reset(d, 1);
  long i = 0;
  double cohorts = 0;
  for (auto _ : state) {
    Control(**p, d, regime, i++);
    mj_step(m, d);
    cohorts += (*p)->NumCohorts(d, 0);
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["cohorts"] = cohorts / state.iterations();
  state.SetLabel(regime == Regime::kFig4Step ? "fig4_step" : "random_switching");
  mj_deleteData(d);
  p.value().reset();
  mj_deleteModel(m);
}
BENCHMARK(BM_Sma)
    ->ArgNames({"units", "regime", "update_ms"})
    ->Args({60, 0, 0})
    ->Args({600, 0, 0})
    ->Args({6000, 0, 0})
    ->Args({60, 1, 0})
    ->Args({600, 1, 0})
    ->Args({6000, 1, 0})
    ->Args({60, 1, 10})
    ->Args({600, 1, 10})
    ->Args({6000, 1, 10})
    ->Iterations(48000);  // 48 simulated seconds: three Fig. 4 cycles

// CPU time of this thread: blocks are not charged for time the thread spends preempted.
double ThreadCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// Interleaved blocks of 1000 steps of each model; counter "ratio" = SMA CPU time / muscle CPU
// time. truth 0: without the plugin's ground-truth sensor, which the muscle bench has no
// counterpart of (the bench's other three sensors are in both). bins > 0: unit_model=binned.
void BM_SmaOverMuscle(benchmark::State& state) {
  const auto regime = static_cast<Regime>(state.range(0));
  const int update_ms = static_cast<int>(state.range(1));
  const bool truth = state.range(2) != 0;
  const int bins = static_cast<int>(state.range(3));
  mjModel* mm = Load(ModelPath("isometric_bench_muscle.xml"));
  mjModel* ms = Load(BenchWithUnits(60, update_ms, truth, bins));
  auto p = SmaHost::Create(ms);
  mjData* dm = mj_makeData(mm);
  mjData* ds = mj_makeData(ms);
  dm->ctrl[0] = 1;
  (*p)->Reset(ds, 1);
  double t_muscle = 0, t_sma = 0, cohorts = 0;
  long i = 0;
  for (auto _ : state) {
    const double t0 = ThreadCpuSeconds();
    for (int k = 0; k < 1000; ++k) mj_step(mm, dm);
    const double t1 = ThreadCpuSeconds();
    for (int k = 0; k < 1000; ++k) {
      Control(**p, ds, regime, i++);
      mj_step(ms, ds);
    }
    cohorts += (*p)->NumCohorts(ds, 0);
    const double t2 = ThreadCpuSeconds();
    t_muscle += t1 - t0;
    t_sma += t2 - t1;
  }
  state.counters["ratio"] = t_sma / t_muscle;
  state.counters["cohorts"] = cohorts / state.iterations();  // at the end of each block
  state.counters["muscle_steps_per_s"] = 1000.0 * state.iterations() / t_muscle;
  state.counters["sma_steps_per_s"] = 1000.0 * state.iterations() / t_sma;
  state.SetLabel(regime == Regime::kFig4Step ? "fig4_step" : "random_switching");
  mj_deleteData(dm);
  mj_deleteData(ds);
  p.value().reset();
  mj_deleteModel(mm);
  mj_deleteModel(ms);
}
BENCHMARK(BM_SmaOverMuscle)
    ->ArgNames({"regime", "update_ms", "truth", "bins"})
    ->Args({0, 0, 1, 0})
    ->Args({1, 0, 1, 0})
    ->Args({1, 10, 1, 0})
    ->Args({0, 0, 0, 0})
    ->Args({1, 0, 0, 0})
    ->Args({1, 10, 0, 0})
    ->Args({1, 0, 1, 8})
    ->Args({1, 0, 1, 12})
    ->Args({1, 0, 1, 16})
    ->Iterations(48);

// The cohort update's kernels side by side on n cohorts that transform at every step (each
// switched every 1.5 s, 0.7 s apart), interleaved in blocks of 1000 steps: counter "ratio" =
// n cohorts' fields, every cohort at `rest`, with the view AdvanceCohorts takes.
struct CohortFields {
  std::vector<double> on, T, xi, te, hs, cs;
  CohortFields(int n, const recruit::sma::UnitState& rest)
      : on(n, 0),
        T(n, rest.temperature),
        xi(n, rest.xi),
        te(n, rest.t_eff),
        hs(n, rest.heat_scale),
        cs(n, rest.cool_scale) {}
  recruit::sma::UnitModel::Cohorts View() {
    return {on.data(), T.data(), xi.data(), te.data(), hs.data(), cs.data()};
  }
};

// AVX-512 CPU time / AVX2 CPU time (UnitModel::AdvanceCohorts takes AVX2 for up to 4 cohorts).
void BM_KernelAvx512OverAvx2(benchmark::State& state) {
  using recruit::sma::UnitModel;
  const int n = static_cast<int>(state.range(0));
  if (!UnitModel::HasAvx512()) return state.SkipWithError("no AVX-512 kernel on this CPU");
  const recruit::sma::UnitParams params;
  auto model = UnitModel::Create(params);
  const double stretch = params.prestretch, decay = model->DecayFactor(1e-3);
  const recruit::sma::UnitState rest = recruit::sma::RestState(*model, stretch);
  CohortFields f[2] = {CohortFields(n, rest), CohortFields(n, rest)};
  const UnitModel::Isa isa[2] = {UnitModel::Isa::kAvx2, UnitModel::Isa::kAvx512};
  double t[2] = {0, 0};
  long i0 = 0;
  for (auto _ : state) {
    for (int k = 0; k < 2; ++k) {
      CohortFields& x = f[k];
      const UnitModel::Cohorts c = x.View();
      const double start = ThreadCpuSeconds();
      for (long i = i0; i < i0 + 1000; ++i) {
        for (int j = 0; j < n; ++j) x.on[j] = ((i + 700 * j) / 1500) % 2;
        model->AdvanceCohorts(c, n, stretch, decay, isa[k]);
      }
      t[k] += ThreadCpuSeconds() - start;
    }
    i0 += 1000;
  }
  if (f[0].xi != f[1].xi || f[0].T != f[1].T) state.SkipWithError("kernels differ");
  state.counters["ratio"] = t[1] / t[0];
  state.counters["avx2_ns"] = 1e9 * t[0] / (1000.0 * state.iterations());
  state.counters["avx512_ns"] = 1e9 * t[1] / (1000.0 * state.iterations());
}
BENCHMARK(BM_KernelAvx512OverAvx2)->ArgName("cohorts")->DenseRange(2, 8)->Iterations(400);

// The cohort update with the telemetry a run loop reads after each step (`recruit simulate`),
// on n cohorts that transform at every step (each switched every 1.5 s, 0.7 s apart), two ways
// interleaved in blocks of 1000 steps: the update giving the telemetry on its way
// (UnitModel::AdvanceCohorts with BatchObserve, kAuto: one or two SIMD blocks, the scalar update
// for a fifth cohort) and, as the reference, the same update followed by the separate pass the
// run loop took before (SumTelemetry and the largest temperature). Counter "ratio" = fused CPU
// time / reference CPU time; both end with the same cohorts and telemetry, bit for bit.
void BM_ObservedUpdateOverSeparatePass(benchmark::State& state) {
  using recruit::sma::UnitModel;
  const int n = static_cast<int>(state.range(0));
  const recruit::sma::UnitParams params;
  auto model = UnitModel::Create(params);
  const double stretch = params.prestretch, decay = model->DecayFactor(1e-3);
  const recruit::sma::UnitState rest = recruit::sma::RestState(*model, stretch);
  struct Fields : CohortFields {
    using CohortFields::CohortFields;
    double out[6];
  } f[2] = {Fields(n, rest), Fields(n, rest)};
  std::vector<double> count(n);
  for (int j = 0; j < n; ++j) count[j] = 1 + (7 * j) % 11;
  double t[2] = {0, 0};
  long i0 = 0, given = 0;
  for (auto _ : state) {
    for (int k = 0; k < 2; ++k) {
      Fields& x = f[k];
      const UnitModel::Cohorts c = x.View();
      const double* v[3] = {x.on.data(), x.T.data(), x.xi.data()};
      const double start = ThreadCpuSeconds();
      for (long i = i0; i < i0 + 1000; ++i) {
        for (int j = 0; j < n; ++j) x.on[j] = ((i + 700 * j) / 1500) % 2;
        recruit::sma::BatchObserve obs;
        obs.count = count.data();
        obs.stretch = stretch;
        model->AdvanceCohorts(c, n, stretch, decay, UnitModel::Isa::kAuto, k == 0 ? &obs : nullptr);
        if (k == 0 && obs.done) {
          ++given;
          for (int q = 0; q < 6; ++q) x.out[q] = obs.out[q];
        } else {
          model->SumTelemetry(count.data(), v, n, stretch, true, x.out);
          double hottest = x.T[0];
          for (int j = 1; j < n; ++j) hottest = x.T[j] > hottest ? x.T[j] : hottest;
          x.out[5] = hottest;
        }
        benchmark::DoNotOptimize(x.out);
      }
      t[k] += ThreadCpuSeconds() - start;
    }
    i0 += 1000;
  }
  if (f[0].xi != f[1].xi || f[0].T != f[1].T) state.SkipWithError("updates differ");
  for (int q = 0; q < 6; ++q) {
    if (f[0].out[q] != f[1].out[q]) state.SkipWithError("telemetry differs");
  }
  state.counters["ratio"] = t[0] / t[1];
  state.counters["fused_ns"] = 1e9 * t[0] / (1000.0 * state.iterations());
  state.counters["separate_ns"] = 1e9 * t[1] / (1000.0 * state.iterations());
  state.counters["fused_share"] = static_cast<double>(given) / (1000.0 * state.iterations());
}
BENCHMARK(BM_ObservedUpdateOverSeparatePass)->ArgName("cohorts")->DenseRange(1, 9)->Iterations(200);

}  // namespace
