// Failure settings as sweep axes (docs/sweep.md): sweep files take "kalman-failures", a
// "/failures/BUNDLE/KEY" axis reaches a task without failures, and the report's tracking figure
// gives each axis value the tracking RMSE of the recommended dT's cell (computed here by hand).
#include <gtest/gtest.h>

#include <filesystem>

#include "sim/task.h"
#include "sweep/recommend.h"
#include "sweep/sweep_file.h"
#include "sweep/sweep_report.h"

namespace recruit::sweep {
namespace file_failure_axis_test {

namespace fs = std::filesystem;

TEST(FailureAxis, SweepFilesTakeTheFailureEstimator) {
  auto ok = SweepFile::FromJsonText(
      R"({"controller": {"estimator": ["kalman-augmented", "kalman-failures"]}})", "s.json");
  ASSERT_TRUE(ok.ok()) << ok.error();
  EXPECT_EQ(ok->estimators.back(), "kalman-failures");
  auto bad = SweepFile::FromJsonText(R"({"controller": {"estimator": "kalman-broken"}})", "s.json");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().find("\"kalman-broken\"; allowed: output, kalman2, kalman-augmented, "
                             "kalman-failures"),
            std::string::npos)
      << bad.error();
}

TEST(FailureAxis, AFailureKeyAxisReachesATaskWithoutFailures) {
  const std::string model = fs::path(RECRUIT_SOURCE_DIR "/models/isometric_bench.xml").string();
  const std::string task = R"({"name": "t", "model": ")" + model + R"(", "tracked": "force",
      "agonist": "bundle", "duration": 5, "reference": {"type": "constant", "value": 5}})";
  auto f = SweepFile::FromJsonText(R"({"plant": {"axes": [
      {"name": "rate", "path": "/failures/bundle/open_rate", "values": [2.5]}]}})",
                                   "s.json");
  ASSERT_TRUE(f.ok()) << f.error();
  auto points = PlantPoints(*f);
  ASSERT_TRUE(points.ok());
  auto in = ApplyPlantPoint(task, "", f->axes, points->at(0), "s.json");
  ASSERT_TRUE(in.ok()) << in.error();
  auto t = sim::Task::FromJsonText(in->task_text, "t.json");
  ASSERT_TRUE(t.ok()) << t.error();
  ASSERT_EQ(t->failures.size(), 1u);
  EXPECT_EQ(t->failures[0].actuator, "bundle");
  EXPECT_EQ(t->failures[0].keys.at(0), (std::pair<std::string, std::string>{"open_rate", "2.5"}));
}

// Two plant points (lost 0 and 6) x dT {0.5, 1}: at 0 lost both dT meet the criterion (the
// recommended is 0.5), at 6 only dT = 1 does. The figure's points are those cells' RMSE.
TEST(FailureAxis, TrackingFigureGivesTheRecommendedCellsRmse) {
  ReportInput in;
  in.title = "t";
  in.unit = "N";
  const double rmse[2][2] = {{0.3, 0.4}, {0.9, 0.5}};  // [plant][dT index]
  for (int p = 0; p < 2; ++p) {
    for (int k = 0; k < 2; ++k) {
      CellStats c;
      c.plant = p;
      c.plant_values = {{"lost", p == 0 ? 0.0 : 6.0}};
      c.dT = k == 0 ? 0.5 : 1.0;
      c.lambda = 0.2;
      c.estimator = "kalman-failures";
      c.seeds = 2;
      c.mean.at(sim::MetricIndex(&sim::RunMetrics::tracking_rmse)) = rmse[p][k];
      c.meets = !(p == 1 && k == 0);
      c.margin = c.meets ? 0.1 : -0.1;
      c.seeds_meeting = c.meets ? 2 : 0;
      in.cells.push_back(c);
    }
  }
  std::vector<plot::Figure> drawn;
  auto render = [&](const plot::Figure& fig, int, int, plot::Format) -> Result<std::string> {
    drawn.push_back(fig);
    return std::string("x");
  };
  const fs::path dir = fs::temp_directory_path() / "recruit_failure_axis_report";
  fs::create_directories(dir);
  ASSERT_TRUE(WriteReport(in, dir.string(), render).ok());
  const plot::Figure* tracking = nullptr;
  for (const auto& f : drawn) {
    if (f.title.find("tracking RMSE") != std::string::npos) tracking = &f;
  }
  ASSERT_NE(tracking, nullptr);
  ASSERT_EQ(tracking->panels.size(), 1u);
  ASSERT_EQ(tracking->panels[0].series.size(), 1u);
  const plot::Series& s = tracking->panels[0].series[0];
  EXPECT_EQ(s.x, (std::vector<double>{0, 6}));
  EXPECT_EQ(s.y, (std::vector<double>{0.3, 0.5}));
  EXPECT_EQ(tracking->panels[0].y_label, "tracking RMSE at dT (N)");
}

}  // namespace file_failure_axis_test
}  // namespace recruit::sweep
