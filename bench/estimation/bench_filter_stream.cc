// Throughput of the streamed offline run (`recruit filter`: FilterLogReader + RunFilterStream
// into an AtomicFile, the code path of src/cli/filter_command.cc) over generated logs of
// 1e6 rows, against the reference of the same run: copying the same log file to an output file
// in 1 MiB chunks (the raw read + write, no parsing). range(0) = m: 2 (the two-state model) or
// 20 (the heating / cooling chain, BroadcastTransitionModel::HeatingChain), both broadcast
// models with r = 1 and the extended Kalman filter. Counter rows_per_s = rows / wall time.
#include <benchmark/benchmark.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "common/atomic_file.h"
#include "common/rng.h"
#include "estimation/count_filter.h"
#include "estimation/filter_log.h"
#include "estimation/filter_model.h"

namespace recruit {
namespace {

constexpr int kRows = 1000000;

estimation::FilterModel Model(int m) {
  if (m == 2) return estimation::FilterModel::TwoState(60, 0.5, 0.45, 0.3);
  estimation::FilterModel f = estimation::FilterModel::TwoState(60, 0.5, 0.45, 0.3);
  f.broadcast = estimation::BroadcastTransitionModel::HeatingChain(m, 0.5);
  f.state_names = f.broadcast.state_names;
  f.H = Eigen::MatrixXd::Zero(1, m);
  const int h = m / 2;
  for (int i = 1; i < m; ++i) f.H(0, i) = i <= h ? 0.45 * i / h : 0.45 * (m - i) / (m - h);
  f.x0 = Eigen::VectorXd::Zero(m);
  f.x0(0) = 60;
  f.P0 = Eigen::MatrixXd::Zero(m, m);
  f.G = Eigen::MatrixXd::Zero(m, 0);
  return f;
}

// t,p_on,p_off,y with 4-6 significant digits, as a controller log would have them.
std::string LogPath(int m) {
  const std::string path = std::filesystem::temp_directory_path().string() +
                           "/recruit_bench_filter_log_m" + std::to_string(m) + ".csv";
  if (std::filesystem::exists(path)) return path;
  Rng rng(11);
  std::string text = "t,p_on,p_off,y\n";
  char line[128];
  for (int k = 0; k < kRows; ++k) {
    const double y = 13.5 + 6.0 * std::sin(k * 1e-3) + 0.3 * (rng.Uniform() - 0.5);
    std::snprintf(line, sizeof line, "%.1f,%.4f,%.4f,%.4f\n", 0.5 * k, 0.3 * rng.Uniform(),
                  0.3 * rng.Uniform(), y);
    text += line;
  }
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

std::string OutPath() {
  return std::filesystem::temp_directory_path().string() + "/recruit_bench_filter_out.csv";
}

void BM_FilterStream(benchmark::State& state) {
  const int m = static_cast<int>(state.range(0));
  const estimation::FilterModel model = Model(m);
  const std::string log_path = LogPath(m);
  for (auto _ : state) {
    auto filter = estimation::MakeCountFilter(model, {});
    auto log = estimation::FilterLogReader::OpenFile(log_path, model);
    AtomicFile out(OutPath(), std::ios::out | std::ios::binary);
    Status s = estimation::RunFilterStream(model, **log, **filter, out.stream());
    if (s.ok()) s = out.Commit();
    if (!s.ok()) {
      state.SkipWithError(s.error().c_str());
      return;
    }
  }
  state.counters["rows_per_s"] = benchmark::Counter(static_cast<double>(kRows) * state.iterations(),
                                                    benchmark::Counter::kIsRate);
  state.counters["out_MB"] = static_cast<double>(std::filesystem::file_size(OutPath())) * 1e-6;
}
BENCHMARK(BM_FilterStream)->Arg(2)->Arg(20)->Unit(benchmark::kMillisecond)->UseRealTime();

// The reference: the same log copied to an output file in 1 MiB chunks.
void BM_RawCopy(benchmark::State& state) {
  const std::string log_path = LogPath(static_cast<int>(state.range(0)));
  std::vector<char> buf(size_t{1} << 20);
  for (auto _ : state) {
    std::FILE* in = std::fopen(log_path.c_str(), "rb");
    AtomicFile out(OutPath(), std::ios::out | std::ios::binary);
    size_t n;
    while ((n = std::fread(buf.data(), 1, buf.size(), in)) > 0) {
      out.stream().write(buf.data(), static_cast<std::streamsize>(n));
    }
    std::fclose(in);
    if (Status s = out.Commit(); !s.ok()) {
      state.SkipWithError(s.error().c_str());
      return;
    }
  }
  state.counters["rows_per_s"] = benchmark::Counter(static_cast<double>(kRows) * state.iterations(),
                                                    benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RawCopy)->Arg(2)->Arg(20)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace recruit
