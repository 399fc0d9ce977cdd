// The bench log reader (src/estimation/bench_log.h) on hand-written logs.
#include "estimation/bench_log.h"

#include <gtest/gtest.h>

namespace recruit {
namespace file_bench_log_test {

constexpr char kHeader[] =
    "time,reference,angle,a.force,a.p_on,a.p_off,b.p_on,b.p_off,control_instant,a.sensed_force,"
    "b.sensed_force\n";

TEST(BenchLog, KeepsTheControlInstantsOfASimulatedLog) {
  // Rows between instants (control_instant 0) are skipped; unknown columns ignored.
  const std::string text = std::string(kHeader) +
                           "0.002,0,0.1,5,0.5,0,0.25,0.125,1,4.5,1\n"
                           "0.004,0,0.2,5,0.5,0,0.25,0.125,0,4.5,1\n"
                           "# a comment\n"
                           "\n"
                           "0.502,0,0.3,6,0,1,0,0,1,5.5,2\n";
  auto log = estimation::ParseBenchLog(text, "sim.csv");
  ASSERT_TRUE(log.ok()) << log.error();
  ASSERT_EQ(log->size(), 2);
  EXPECT_DOUBLE_EQ(log->dT, 0.5);
  ASSERT_EQ(log->bundles.size(), 2u);
  EXPECT_EQ(log->bundles[0].name, "a");
  EXPECT_EQ(log->bundles[1].name, "b");
  EXPECT_EQ(log->bundles[0].sensed_force, (std::vector<double>{4.5, 5.5}));
  EXPECT_EQ(log->bundles[1].p_off, (std::vector<double>{0.125, 0}));
  ASSERT_EQ(log->angles.size(), 1u);
  EXPECT_EQ(log->angles[0].value, (std::vector<double>{0.1, 0.3}));
  EXPECT_EQ(log->line, (std::vector<int>{2, 6}));
}

TEST(BenchLog, WithoutControlInstantEveryRowIsOne) {
  auto log = estimation::ParseBenchLog(
      "time,x.p_on,x.p_off,x.sensed_force\n10,0.5,0,0\n10.5,0,0,1\n11,0,0.5,2\n", "rig.csv");
  ASSERT_TRUE(log.ok()) << log.error();
  EXPECT_EQ(log->size(), 3);
  EXPECT_DOUBLE_EQ(log->dT, 0.5);
  EXPECT_TRUE(log->angles.empty());
}

TEST(BenchLog, RejectsBadLogsNamingFileLineColumnAndValue) {
  const std::string h = "time,x.p_on,x.p_off,x.sensed_force\n";
  struct Case {
    std::string text, message;
  } cases[] = {
      {"time,x.p_on,x.sensed_force\n0,0,0\n", "needs its bundle's broadcast columns 'x.p_on' and"},
      {"t,x.p_on,x.p_off,x.sensed_force\n", "needs a 'time' column"},
      {h + "0,0,0,0\n1,1.5,0,0\n", "log.csv:3: column 'x.p_on': '1.5' is not a finite number in"},
      {h + "0,0,0,0\n1,0,0,nan\n", "log.csv:3: column 'x.sensed_force': 'nan'"},
      {h + "0,0,0,0\n1,0,0\n", "log.csv:3: has 3 cells, the header 4"},
      {h + "0,0,0,0\n1,0,0,0\n2.5,0,0,0\n",
       "log.csv:3: control period 1 s differs from the mean 1.25 s"},
      {h + "0,0,0,0\n0,0,0,0\n", "log.csv:3: time 0 s does not increase"},
      {h + "0,0,0,0\n", "needs at least 2 control instants, has 1"},
      {"time,control_instant,x.p_on,x.p_off,x.sensed_force\n0,yes,0,0,0\n",
       "log.csv:2: column 'control_instant': 'yes' must be 0 or 1"},
      {"time,time,x.p_on,x.p_off,x.sensed_force\n", "duplicate column 'time'"},
      {"", "empty log"},
  };
  for (const Case& c : cases) {
    auto log = estimation::ParseBenchLog(c.text, "log.csv");
    ASSERT_FALSE(log.ok()) << c.text;
    EXPECT_NE(log.error().find(c.message), std::string::npos) << log.error();
  }
}

TEST(BenchLog, SelectsABundleByName) {
  auto cols = estimation::FindBenchLogColumns(
      {"time", "a.p_on", "a.p_off", "a.sensed_force", "b.p_on", "b.p_off", "b.sensed_force"},
      "f.csv");
  ASSERT_TRUE(cols.ok());
  EXPECT_EQ(*estimation::SelectBenchBundle(*cols, "b", "f.csv"), 1);
  auto none = estimation::SelectBenchBundle(*cols, "", "f.csv");
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.error().find("several bundles (a, b)"), std::string::npos);
  auto wrong = estimation::SelectBenchBundle(*cols, "c", "f.csv");
  ASSERT_FALSE(wrong.ok());
  EXPECT_NE(wrong.error().find("no bundle 'c' in the log; it has a, b"), std::string::npos);
}

}  // namespace file_bench_log_test
}  // namespace recruit
