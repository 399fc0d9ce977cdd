// The table of run metrics (sim/run_metrics.h) against the struct it describes and the outputs it
// drives: every field of RunMetrics is in the table (counted by brace initialisation, not by the
// table); a summary with every metric distinct survives the JSON writer and the sweep's record
// reader field by field; table.csv's header and row carry each tabled metric's mean over seeds.
#include "sim/run_metrics.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <utility>

#include "sim/run_task.h"
#include "sweep/grid.h"
#include "sweep/table.h"

namespace recruit::sim {
namespace file_run_metrics_test {

namespace fs = std::filesystem;
using namespace ::recruit::sweep;  // NOLINT: the sweep code under test (src/sweep)

// The number of fields of an aggregate: the largest N for which T{x1, ..., xN} compiles.
struct AnyValue {
  template <class U>
  operator U() const;
};
template <class T, std::size_t... I>
constexpr auto BraceInitializable(std::index_sequence<I...>)
    -> decltype(T{(void(I), AnyValue{})...}, true) {
  return true;
}
template <class T>
constexpr bool BraceInitializable(...) {
  return false;
}
template <class T, std::size_t N = 0>
constexpr std::size_t FieldCount() {
  if constexpr (BraceInitializable<T>(std::make_index_sequence<N + 1>{})) {
    return FieldCount<T, N + 1>();
  } else {
    return N;
  }
}

static_assert(FieldCount<RunMetrics>() == kMetricCount,
              "RunMetrics has a field kMetricFields (sim/run_metrics.h) does not list");

// Every metric a distinct value, a count whole; set through the members by name (not the table).
RunMetrics Distinct() {
  RunMetrics m;
  m.tracking_rmse = 1.25;
  m.iae = 2.5;
  m.overshoot = 0.125;
  m.max_overshoot = 0.375;
  m.settling_time = 3.75;
  m.settled_fraction = 0.625;
  m.oscillation = 0.0625;
  m.switching_rate = 0.03125;
  m.estimator_rmse = 4.5;
  m.mean_nees = 0.875;
  m.estimator_within3 = 0.8125;
  m.num_steps = 7;
  return m;
}

TEST(RunMetricsTable, EachFieldOnceWithOnePointerAndAUnit) {
  std::set<std::string> names;
  std::set<std::string> columns;
  for (const MetricField& f : kMetricFields) {
    EXPECT_TRUE(names.insert(f.name).second) << f.name;
    EXPECT_NE(f.real == nullptr, f.count == nullptr) << f.name;
    EXPECT_GT(std::string(f.unit).size(), 0u) << f.name;
    if (f.cell_mean) {
      EXPECT_TRUE(columns.insert(f.cell_mean).second) << f.cell_mean;
    }
  }
  // Distinct members: with every value distinct, no two entries read the same one.
  const RunMetrics m = Distinct();
  std::set<double> values;
  for (const MetricField& f : kMetricFields) values.insert(MetricValue(m, f));
  EXPECT_EQ(values.size(), kMetricCount);
}

TEST(RunMetricsTable, JsonNamesEachMember) {
  const RunMetrics m = Distinct();
  const nlohmann::json j = MetricsToJson(m);
  EXPECT_EQ(j.size(), FieldCount<RunMetrics>());
  // The key of each member, written out here independently of the table.
  EXPECT_EQ(j.at("tracking_rmse").get<double>(), m.tracking_rmse);
  EXPECT_EQ(j.at("iae").get<double>(), m.iae);
  EXPECT_EQ(j.at("overshoot").get<double>(), m.overshoot);
  EXPECT_EQ(j.at("max_overshoot").get<double>(), m.max_overshoot);
  EXPECT_EQ(j.at("settling_time").get<double>(), m.settling_time);
  EXPECT_EQ(j.at("settled_fraction").get<double>(), m.settled_fraction);
  EXPECT_EQ(j.at("oscillation").get<double>(), m.oscillation);
  EXPECT_EQ(j.at("switching_rate").get<double>(), m.switching_rate);
  EXPECT_EQ(j.at("estimator_rmse").get<double>(), m.estimator_rmse);
  EXPECT_EQ(j.at("mean_nees").get<double>(), m.mean_nees);
  EXPECT_EQ(j.at("estimator_within3").get<double>(), m.estimator_within3);
  EXPECT_TRUE(j.at("num_steps").is_number_integer());
  EXPECT_EQ(j.at("num_steps").get<int>(), m.num_steps);
}

RunSummary Summary(const RunMetrics& m) {
  RunSummary s;
  s.task = "t";
  s.estimator = "output";
  s.dT = 0.5;
  s.lambda = 0.2;
  s.seed = 9;
  s.duration = 10;
  s.unit = "N";
  s.metrics = m;
  return s;
}

// Through the text of a record file: RunSummary::ToJson, dump, parse, RunSummaryFromJson.
RunSummary RoundTrip(const RunSummary& s) {
  auto back = RunSummaryFromJson(nlohmann::json::parse(s.ToJson().dump(1)));
  EXPECT_TRUE(back.ok()) << back.error();
  return back.ok() ? *back : RunSummary{};
}

TEST(RunMetricsTable, SummaryRoundTripsEveryMetric) {
  const RunSummary s = Summary(Distinct());
  const RunSummary back = RoundTrip(s);
  for (const MetricField& f : kMetricFields) {
    EXPECT_EQ(MetricValue(back.metrics, f), MetricValue(s.metrics, f)) << f.name;
  }
  // A second, independent look at two members.
  EXPECT_EQ(back.metrics.estimator_within3, 0.8125);
  EXPECT_EQ(back.metrics.num_steps, 7);
}

TEST(RunMetricsTable, NanMetricIsNullAndBack) {
  RunMetrics m = Distinct();
  m.mean_nees = std::nan("");
  const RunSummary s = Summary(m);
  EXPECT_NE(s.ToJson().dump().find("\"mean_nees\":null"), std::string::npos);
  EXPECT_TRUE(std::isnan(RoundTrip(s).metrics.mean_nees));
}

TEST(RunMetricsTable, MissingKeyIsNamed) {
  nlohmann::json j = Summary(Distinct()).ToJson();
  j["metrics"].erase("oscillation");
  const auto back = RunSummaryFromJson(j);
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.error().find("oscillation"), std::string::npos) << back.error();
}

std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  for (std::string cell; std::getline(ss, cell, ',');) out.push_back(cell);
  return out;
}

// table.csv of two seeds of one cell: each tabled metric's column holds the mean of the seeds,
// overshoot_sd their sample standard deviation; the metrics left out are the ones stated here.
TEST(RunMetricsTable, SweepTableHasEveryTabledMetricsMean) {
  RunMetrics a = Distinct(), b = Distinct();
  for (const MetricField& f : kMetricFields) SetMetric(b, f, 3 * MetricValue(a, f) + 1);
  const std::vector<RunSummary> runs = {Summary(a), Summary(b)};
  const TrackingCriterion crit;
  const fs::path dir = fs::temp_directory_path() / "recruit_run_metrics_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  ASSERT_TRUE(WriteTables(Aggregate(runs, crit), crit, dir.string(), "metrics").ok());
  std::ifstream in(dir / "table.csv");
  std::string head, row;
  std::getline(in, head);
  std::getline(in, row);
  const std::vector<std::string> names = SplitCsv(head), values = SplitCsv(row);
  ASSERT_EQ(names, CellColumns());
  ASSERT_EQ(values.size(), names.size());
  auto value_of = [&](const std::string& column) {
    for (size_t i = 0; i < names.size(); ++i) {
      if (names[i] == column) return values[i];
    }
    ADD_FAILURE() << "table.csv has no column " << column;
    return std::string();
  };
  std::set<std::string> left_out;
  for (const MetricField& f : kMetricFields) {
    if (!f.cell_mean) {
      left_out.insert(f.name);
      continue;
    }
    const double x = MetricValue(a, f), y = MetricValue(b, f);
    // The table's numbers read back exactly (shortest round trip); the sd to rounding.
    EXPECT_EQ(std::stod(value_of(f.cell_mean)), (x + y) / 2) << f.name;
    if (f.cell_sd) {
      EXPECT_DOUBLE_EQ(std::stod(value_of(std::string(f.name) + "_sd")),
                       std::abs(x - y) / std::sqrt(2.0))
          << f.name;
    }
  }
  EXPECT_EQ(left_out, (std::set<std::string>{"max_overshoot", "num_steps"}));
  EXPECT_DOUBLE_EQ(std::stod(value_of("overshoot_sd")), (3 * 0.125 + 1 - 0.125) / std::sqrt(2.0));
  fs::remove_all(dir);
}

}  // namespace file_run_metrics_test
}  // namespace recruit::sim
