// The per-step CSV's rows (CsvStepWriter::OnStep) against the previous writer's method in the
// same run: every changed value formatted in full by FormatG (its text cached per column, as
// before this pass). The rows are a force task's: the time on the 2 ms grid, a measured force
// that moves a little each step (and is the bundle's force), a temperature rising a little each
// step, and the controller's columns changing once every 500 steps (docs/benchmarks.md, "The
// CSV's changed values").
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <vector>

#include "common/telemetry.h"
#include "sim/csv_writer.h"
#include "sim/format_g.h"

namespace recruit::sim {
namespace {

std::vector<TelemetrySample> ForceTaskRows(int n) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0, 1);
  std::vector<TelemetrySample> rows(static_cast<std::size_t>(n));
  double t = 0, force = 0, temperature = 20;
  TelemetrySample s;
  s.bundles.resize(1);
  s.bundles[0].actuator = "bundle";
  s.bundles[0].estimated_on = 0;
  s.bundles[0].estimated_on_std = 0;
  for (int i = 0; i < n; ++i) {
    t += 0.002;
    s.time = t;
    s.control_instant = i % 500 == 0;
    auto& b = s.bundles[0];
    if (s.control_instant) {
      s.reference = 12 + static_cast<double>(i / 7500 % 3) * 6;
      b.force_reference = s.reference;
      b.true_on = static_cast<int>(rng() % 40);
      b.estimated_on = 20 + noise(rng);
      b.estimated_on_std = 0.7 + 0.05 * noise(rng);
      b.p_on = 0.01 * std::abs(noise(rng));
      b.sensed_force = 0.0125 * std::round(force / 0.0125);
    }
    force += 1e-3 * noise(rng);
    temperature += 0.018 + 1e-3 * noise(rng);
    if (temperature > 90) temperature = 20;
    s.measured = force;
    b.force = force;
    b.mean_temperature = temperature;
    rows[static_cast<std::size_t>(i)] = s;
  }
  return rows;
}

// The previous writer's row (a one-bundle layout): each column's last value and text, a changed
// value formatted by FormatG.
class PreviousRows {
 public:
  explicit PreviousRows(const std::string& path) : out_(path, std::ios::binary) {
    buffer_.resize(1 << 17);
  }
  void Row(const TelemetrySample& s) {
    char* p = buffer_.data() + used_;
    Column* col = cache_;
    auto num = [&](double v, int precision) __attribute__((always_inline)) {
      Column& c = *col++;
      std::uint64_t bits;
      std::memcpy(&bits, &v, sizeof bits);
      if (c.len == 0 || bits != c.bits) {
        c.bits = bits;
        c.len = static_cast<std::uint8_t>(FormatG(v, precision, c.text) - c.text);
      }
      std::memcpy(p, c.text, sizeof c.text);
      p += c.len;
    };
    num(s.time, 6);
    *p++ = ',';
    num(s.reference, 9);
    *p++ = ',';
    num(s.measured, 9);
    *p++ = ',';
    num(s.angle, 9);
    const auto& b = s.bundles[0];
    *p++ = ',';
    num(b.force, 9);
    *p++ = ',';
    num(b.force_reference, 9);
    *p++ = ',';
    p = FormatInt(b.true_on, p);
    *p++ = ',';
    num(b.estimated_on, 6);
    *p++ = ',';
    num(b.estimated_on_std, 6);
    *p++ = ',';
    num(b.p_on, 6);
    *p++ = ',';
    num(b.p_off, 6);
    *p++ = ',';
    num(b.mean_temperature, 6);
    *p++ = ',';
    *p++ = s.control_instant ? '1' : '0';
    *p++ = ',';
    num(b.sensed_force, 9);
    *p++ = '\n';
    used_ = static_cast<std::size_t>(p - buffer_.data());
    if (used_ > 64 * 1024) Flush();
  }
  void Flush() {
    out_.write(buffer_.data(), static_cast<std::streamsize>(used_));
    used_ = 0;
  }

 private:
  struct Column {
    std::uint64_t bits = 0;
    std::uint8_t len = 0;
    char text[kFormatGMax];
  };
  std::ofstream out_;
  std::vector<char> buffer_;
  std::size_t used_ = 0;
  Column cache_[16];
};

const std::vector<TelemetrySample>& Rows() {
  static const std::vector<TelemetrySample> rows = ForceTaskRows(30000);
  return rows;
}

std::string TempCsv(const char* name) {
  return (std::filesystem::temp_directory_path() / name).string();
}

void BM_CsvRows(benchmark::State& state) {
  const auto& rows = Rows();
  for (auto _ : state) {
    CsvStepWriter writer(TempCsv("recruit_csv_row_bench.csv"));
    for (const auto& s : rows) benchmark::DoNotOptimize(writer.OnStep(nullptr, nullptr, s));
    benchmark::DoNotOptimize(writer.Finish());
  }  // not committed: the temporary file is removed
  state.SetItemsProcessed(state.iterations() * static_cast<long>(rows.size()));
}

// The reference: the previous writer's method on the same rows.
void BM_CsvRowsFormatGEachChange(benchmark::State& state) {
  const auto& rows = Rows();
  const std::string path = TempCsv("recruit_csv_row_bench_previous.csv");
  for (auto _ : state) {
    PreviousRows writer(path);
    for (const auto& s : rows) writer.Row(s);
    writer.Flush();
  }
  std::filesystem::remove(path);
  state.SetItemsProcessed(state.iterations() * static_cast<long>(rows.size()));
}

BENCHMARK(BM_CsvRows)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CsvRowsFormatGEachChange)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace recruit::sim
