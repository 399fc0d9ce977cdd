// A reference the working units cannot deliver after units break: the run's summary says so, and
// the loop tracks again once the reference is back within reach (issue: units that fail).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "sim/run_task.h"
#include "sim/task.h"

namespace recruit::sim {
namespace file_saturation_test {

namespace fs = std::filesystem;
const std::string kRoot = RECRUIT_SOURCE_DIR;

// The isometric bench (60 units) with `config` (a <config .../> element) in its bundle's
// instance, and a force task on it: 12 N, then 24 N at 20 s, then 8 N at 40 s.
Result<RunSummary> RunBench(const std::string& config, const std::string& name) {
  std::ifstream in(kRoot + "/models/isometric_bench.xml");
  std::stringstream text;
  text << in.rdbuf();
  std::string xml = text.str();
  const std::string anchor = "<instance name=\"bundle_units\">";
  xml.insert(xml.find(anchor) + anchor.size(), config);
  const fs::path dir = fs::temp_directory_path() / ("recruit_saturation_" + name);
  fs::create_directories(dir);
  std::ofstream(dir / "bench.xml") << xml;
  const std::string task = R"({"name": "sat", "model": "bench.xml", "tracked": "force",
    "agonist": "bundle", "duration": 60,
    "reference": {"type": "steps", "times": [5, 20, 40], "values": [12, 24, 8], "unit": "N"},
    "controller": {"estimator": "kalman-failures", "dT": 0.5, "lambda": 0.2}})";
  auto t = Task::FromJsonText(task, (dir / "task.json").string());
  if (!t.ok()) return Error{t.error()};
  RunOptions o;
  o.seed = 11;
  o.quiet = true;
  return RunTask(*t, o);
}

int OutOfReach(const RunSummary& s) {
  for (const std::string& w : s.warnings) {
    if (w.find("needed more than the working units") != std::string::npos) {
      return std::stoi(w.substr(w.find(" at ") + 4));
    }
  }
  return 0;
}

TEST(Saturation, OutOfReachIsReportedAndTheLoopRecovers) {
  // Half the units open at 10 s: 30 cannot pull the 24 N that 60 could.
  auto broken = RunBench(R"(<config key="failures" value="10:30:open"/>)", "broken");
  ASSERT_TRUE(broken.ok()) << broken.error();
  const int instants = OutOfReach(*broken);
  EXPECT_GT(instants, 10);  // most of the 24 N hold (40 instants)
  EXPECT_LE(instants, 60);  // not the 12 N or 8 N holds
  ASSERT_EQ(broken->steps.size(), 3u);
  EXPECT_TRUE(broken->steps[2].settled);  // back within reach: it tracks again
  auto whole = RunBench("", "whole");
  ASSERT_TRUE(whole.ok()) << whole.error();
  EXPECT_EQ(OutOfReach(*whole), 0);
  EXPECT_TRUE(whole->steps[1].settled);  // 60 units reach 24 N
}

}  // namespace file_saturation_test
}  // namespace recruit::sim
