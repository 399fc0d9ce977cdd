// `recruit filter` and `recruit identify --log` read a bench log as the file in their older
// formats that holds its control instants (t,p_on,p_off,y and time,p_on,p_off,force), written
// here from the bench log's rows: the same output, number for number.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/atomic_file.h"
#include "estimation/bench_log.h"
#include "estimation/count_filter.h"
#include "estimation/filter_log.h"
#include "estimation/filter_model.h"
#include "identification/switching_log.h"
#include "sim/csv_writer.h"
#include "sim/run_task.h"

namespace recruit {
namespace file_readers_test {

namespace fs = std::filesystem;
const std::string kRoot = RECRUIT_SOURCE_DIR;

// A 60 s isometric run's per-step CSV (every 10th step and every control instant), as text.
std::string SimulatedCsv() {
  auto task = sim::Task::FromFile(kRoot + "/models/tasks/isometric_steps.json");
  EXPECT_TRUE(task.ok());
  const std::string path = (fs::temp_directory_path() / "recruit_readers_test.csv").string();
  sim::CsvStepWriter writer(path, 10);
  sim::RunOptions o;
  o.seed = 9;
  o.estimator = "output";
  EXPECT_TRUE(sim::RunTask(*task, o, {&writer}).ok());
  EXPECT_TRUE(writer.Commit().ok());
  auto text = ReadFile(path);
  fs::remove(path);
  return *text;
}

// The bench log's rows in the older format: `names` are its four column names.
std::string OlderFormat(const estimation::BenchLog& log, const char* names) {
  std::string out = std::string(names) + "\n";
  const auto& b = log.bundles[0];
  for (int k = 0; k < log.size(); ++k) {
    out += fmt::format("{},{},{},{}\n", log.time[k], b.p_on[k], b.p_off[k], b.sensed_force[k]);
  }
  return out;
}

TEST(BenchLogReaders, FilterReadsItAsItsOwnLog) {
  const std::string csv = SimulatedCsv();
  auto log = estimation::ParseBenchLog(csv, "sim.csv");
  ASSERT_TRUE(log.ok()) << log.error();
  ASSERT_EQ(log->size(), 60);
  auto model = estimation::FilterModel::FromJson(
      kRoot + "/models/identified/bundle_903e47abb54d0604_dt1_m20.json");
  ASSERT_TRUE(model.ok()) << model.error();
  auto f1 = estimation::MakeCountFilter(*model, {});
  auto f2 = estimation::MakeCountFilter(*model, {});
  auto from_bench = estimation::RunFilterOverText(*model, csv, "sim.csv", **f1);
  auto from_older =
      estimation::RunFilterOverText(*model, OlderFormat(*log, "t,p_on,p_off,y"), "f.csv", **f2);
  ASSERT_TRUE(from_bench.ok()) << from_bench.error();
  ASSERT_TRUE(from_older.ok()) << from_older.error();
  EXPECT_EQ(*from_bench, *from_older);
  // A bundle the log does not have is named with the ones it has.
  auto reader = estimation::FilterLogReader::OpenText(csv, *model, "sim.csv", "flexor");
  ASSERT_FALSE(reader.ok());
  EXPECT_NE(reader.error().find("no bundle 'flexor' in the log; it has bundle"), std::string::npos)
      << reader.error();
}

TEST(BenchLogReaders, IdentifyReadsItAsASwitchingLog) {
  const std::string csv = SimulatedCsv();
  auto log = estimation::ParseBenchLog(csv, "sim.csv");
  ASSERT_TRUE(log.ok());
  const fs::path dir = fs::temp_directory_path();
  const std::string bench = (dir / "recruit_readers_bench.csv").string();
  const std::string older = (dir / "recruit_readers_older.csv").string();
  std::ofstream(bench) << csv;
  std::ofstream(older) << OlderFormat(*log, "time,p_on,p_off,force");
  auto a = identification::SwitchingLog::FromCsv(bench, 60);
  auto b = identification::SwitchingLog::FromCsv(older, 60);
  ASSERT_TRUE(a.ok()) << a.error();
  ASSERT_TRUE(b.ok()) << b.error();
  EXPECT_EQ(a->time, b->time);
  EXPECT_EQ(a->p_on, b->p_on);
  EXPECT_EQ(a->p_off, b->p_off);
  EXPECT_EQ(a->force, b->force);
  EXPECT_NEAR(a->dT, 1.0, 1e-9);
  fs::remove(bench);
  fs::remove(older);
}

}  // namespace file_readers_test
}  // namespace recruit
