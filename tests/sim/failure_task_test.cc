// Failure settings in the task file ("failures", docs/formats/task.md): a task that gives them
// runs exactly as the same task on a model whose plugin instance carries the keys (written by
// hand, the independent reference); bad keys and bundles are errors naming the file, the key and
// the value.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "sim/run_task.h"
#include "sim/task.h"

namespace recruit::sim {
namespace file_failure_task_test {

namespace fs = std::filesystem;
const std::string kRoot = RECRUIT_SOURCE_DIR;

// A force task on `model` (12 N, 24 N at 20 s, 8 N at 40 s) with `extra` fields, kalman-failures.
std::string BenchTask(const std::string& model, const std::string& extra) {
  return R"({"name": "fail", "model": ")" + model + R"(", "tracked": "force",
    "agonist": "bundle", "duration": 50,
    "reference": {"type": "steps", "times": [5, 20, 40], "values": [12, 24, 8], "unit": "N"},
    "controller": {"estimator": "kalman-failures", "dT": 0.5, "lambda": 0.2})" +
         extra + "}";
}

Result<RunSummary> RunText(const std::string& text, const std::string& source) {
  auto t = Task::FromJsonText(text, source);
  if (!t.ok()) return Error{t.error()};
  RunOptions o;
  o.seed = 5;
  o.quiet = true;
  return RunTask(*t, o);
}

TEST(FailureTask, KeysInTheTaskRunAsKeysInTheModel) {
  // The reference: the bench's MJCF with the keys in its instance, written by hand.
  std::ifstream in(kRoot + "/models/isometric_bench.xml");
  std::stringstream text;
  text << in.rdbuf();
  std::string xml = text.str();
  const std::string anchor = "<instance name=\"bundle_units\">";
  xml.insert(
      xml.find(anchor) + anchor.size(),
      R"(<config key="open_rate" value="30"/><config key="failures" value="10:20:open,30:3:stuck"/>)");
  const fs::path dir = fs::temp_directory_path() / "recruit_failure_task";
  fs::create_directories(dir);
  std::ofstream(dir / "bench.xml") << xml;
  auto by_hand = RunText(BenchTask("bench.xml", ""), (dir / "a.json").string());
  ASSERT_TRUE(by_hand.ok()) << by_hand.error();
  auto from_task =
      RunText(BenchTask(kRoot + "/models/isometric_bench.xml", R"(, "failures": {"bundle":
      {"open_rate": 30, "schedule": [{"time": 10, "count": 20, "mode": "open"},
                                     {"time": 30, "count": 3, "mode": "stuck"}]}})"),
              (dir / "b.json").string());
  ASSERT_TRUE(from_task.ok()) << from_task.error();
  EXPECT_EQ(from_task->metrics.tracking_rmse, by_hand->metrics.tracking_rmse);
  EXPECT_EQ(from_task->bundles[0].estimator_rmse, by_hand->bundles[0].estimator_rmse);
  EXPECT_EQ(from_task->warnings, by_hand->warnings);
  // The failures happened: 20 of 60 open cannot pull 24 N.
  bool saturated = false;
  for (const std::string& w : from_task->warnings) {
    saturated |= w.find("needed more than the working units") != std::string::npos;
  }
  EXPECT_TRUE(saturated);
  // Nothing is left beside the model.
  for (const auto& e : fs::directory_iterator(kRoot + "/models")) {
    EXPECT_EQ(e.path().filename().string().find(".isometric_bench.failures"), std::string::npos);
  }
}

// A schedule of 0 units (a sweep's baseline point) is the task without failures, bit for bit.
TEST(FailureTask, ZeroUnitsScheduledIsTheTaskWithoutFailures) {
  const std::string model = kRoot + "/models/isometric_bench.xml";
  auto none = RunText(BenchTask(model, ""), "n.json");
  auto zero = RunText(BenchTask(model, R"(, "failures": {"bundle":
      {"schedule": [{"time": 10, "count": 0, "mode": "open"}]}})"),
                      "z.json");
  ASSERT_TRUE(none.ok() && zero.ok());
  EXPECT_EQ(zero->metrics.tracking_rmse, none->metrics.tracking_rmse);
  EXPECT_EQ(zero->bundles[0].estimator_rmse, none->bundles[0].estimator_rmse);
}

// A bundle that tires (its units' force falls 30 % within about 5 cycles, docs/failures.md):
// with the scale fixed at 1 the filter reads the weaker units as fewer units and its on-count
// NEES leaves the band; with "force_scale_variance" it estimates the scale and stays
// consistent. Any other estimator refuses the key.
TEST(FailureTask, ForceScaleVarianceEstimatesATiringBundlesScale) {
  const std::string model = kRoot + "/models/isometric_bench.xml";
  // 200 s of steps between 4 and 20 N every 10 s: every unit goes through many cycles.
  auto task = [&](const std::string& estimator, const std::string& controller_extra) {
    std::string times, values;
    for (int k = 0; k < 20; ++k) {
      times += (k ? ", " : "") + std::to_string(5 + 10 * k);
      values += (k ? ", " : "") + std::string(k % 2 ? "4" : "20");
    }
    return R"({"name": "tires", "model": ")" + model + R"(", "tracked": "force",
      "agonist": "bundle", "duration": 200,
      "reference": {"type": "steps", "times": [)" +
           times + R"(], "values": [)" + values +
           R"(], "unit": "N"},
      "controller": {"estimator": ")" +
           estimator + R"(", "dT": 0.5, "lambda": 0.2)" + controller_extra + R"(},
      "failures": {"bundle": {"fatigue_loss": 0.3, "fatigue_cycles": 5, "fatigue_exponent": 0}}})";
  };
  auto fixed = RunText(task("kalman-failures", ""), "f.json");
  auto scaled = RunText(task("kalman-failures", R"(, "force_scale_variance": 1e-4)"), "s.json");
  ASSERT_TRUE(fixed.ok()) << fixed.error();
  ASSERT_TRUE(scaled.ok()) << scaled.error();
  EXPECT_GT(fixed->bundles[0].mean_nees, 2.0);
  EXPECT_GE(scaled->bundles[0].mean_nees, 0.3);
  EXPECT_LE(scaled->bundles[0].mean_nees, 2.0);
  EXPECT_LT(scaled->bundles[0].estimator_rmse, fixed->bundles[0].estimator_rmse);
  auto refused = RunText(task("kalman-augmented", R"(, "force_scale_variance": 1e-4)"), "r.json");
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().find("force_scale_variance"), std::string::npos) << refused.error();
  auto negative = RunText(task("kalman-failures", R"(, "force_scale_variance": -1)"), "n.json");
  ASSERT_FALSE(negative.ok());
  EXPECT_NE(negative.error().find("force_scale_variance: -1"), std::string::npos)
      << negative.error();
}

TEST(FailureTask, BadKeysAreNamedWithTheirValueAndWhatIsAllowed) {
  const std::string model = kRoot + "/models/isometric_bench.xml";
  struct Case {
    const char* failures;
    const char* expect;
  };
  const Case cases[] = {
      {R"({"bundle": {"open_rate": -1}})", "t.json.failures.bundle.open_rate: -1 is out of range"},
      {R"({"bundle": {"open_rte": 1}})", "t.json.failures.bundle: unknown field 'open_rte'"},
      {R"({"bundle": {"open_per_cycle": 0.7, "stuck_per_cycle": 0.6}})",
       "open_per_cycle + stuck_per_cycle = 1.3; allowed: at most 1"},
      {R"({"bundle": {"schedule": [{"time": 3, "count": 2, "mode": "broken"}]}})",
       "t.json.failures.bundle.schedule[0].mode: 'broken'; allowed: open, stuck"},
      {R"({"bundle": {"schedule": [{"time": 3, "count": -1, "mode": "open"}]}})",
       "t.json.failures.bundle.schedule[0].count"},
      {R"({"bundle": {}})", "t.json.failures.bundle: gives no failure key"},
      {R"([1])", "t.json.failures: must be an object"},
      {R"({"flexor": {"open_rate": 1}})", "failures.flexor: no SMA bundle 'flexor' in"},
      {R"({"bundle": {"schedule": [{"time": 3, "count": 61, "mode": "open"}]}})", "failures"},
  };
  for (const Case& c : cases) {
    auto r = RunText(BenchTask(model, std::string(R"(, "failures": )") + c.failures), "t.json");
    ASSERT_FALSE(r.ok()) << c.failures;
    EXPECT_NE(r.error().find(c.expect), std::string::npos) << r.error();
  }
}

}  // namespace file_failure_task_test
}  // namespace recruit::sim
