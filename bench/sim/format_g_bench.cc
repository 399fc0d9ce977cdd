// FormatG (the per-step CSV's number formatter) against fmt's "{:.Ng}", which it matches byte for
// byte (docs/benchmarks.md, "Issue 15, session 6"). The values are a CSV row's kinds: a time on
// the 2 ms grid (%.6g), an angle in rad and a tendon force in N (%.9g), a temperature (%.6g).
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <random>
#include <vector>

#include "sim/format_g.h"

namespace recruit::sim {
namespace {

struct Cell {
  double value;
  int precision;
};

std::vector<Cell> RowLikeValues() {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Cell> cells;
  for (int i = 0; i < 4096; ++i) {
    cells.push_back({0.002 * i, 6});
    cells.push_back({1.6 * u(rng), 9});
    cells.push_back({40 * u(rng), 9});
    cells.push_back({20 + 70 * u(rng), 6});
  }
  return cells;
}

void BM_FormatG(benchmark::State& state) {
  const std::vector<Cell> cells = RowLikeValues();
  char out[kFormatGMax];
  for (auto _ : state) {
    for (const Cell& c : cells) {
      benchmark::DoNotOptimize(FormatG(c.value, c.precision, out));
      benchmark::ClobberMemory();
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<long>(cells.size()));
}

// The reference: fmt, as the CSV writer used before FormatG.
void BM_FmtG(benchmark::State& state) {
  const std::vector<Cell> cells = RowLikeValues();
  char out[kFormatGMax];
  for (auto _ : state) {
    for (const Cell& c : cells) {
      benchmark::DoNotOptimize(fmt::format_to(out, "{:.{}g}", c.value, c.precision));
      benchmark::ClobberMemory();
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<long>(cells.size()));
}

BENCHMARK(BM_FormatG);
BENCHMARK(BM_FmtG);

}  // namespace
}  // namespace recruit::sim
