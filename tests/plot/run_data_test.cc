// Reading a run's CSV and summary, and the figures built from them: the count panel's band is
// estimated_on +- 2 estimated_on_std row by row (checked against numbers parsed here from the
// text), absent when there is no standard deviation; true and estimated counts differ in style.
#include "plot/run_data.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "plot/run_figures.h"

namespace recruit::plot {
namespace file_run_data_test {

const char* kHeader =
    "time,reference,measured,angle,b.force,b.force_reference,b.true_on,b.estimated_on,"
    "b.estimated_on_std,b.p_on,b.p_off,b.mean_temperature,control_instant\n";

std::string Csv(bool with_std) {
  std::string s = kHeader;
  s += "0,0,0,0,0,0,0,,,0.1,0,20,1\n";
  s += with_std ? "0.5,8,1,0,1,8,3,2.5,0.5,0.1,0,25,1\n" : "0.5,8,1,0,1,8,3,2.5,,0.1,0,25,1\n";
  s += with_std ? "1,8,2,0,2,8,5,4.75,0.25,0,0,30,1\n" : "1,8,2,0,2,8,5,4.75,,0,0,30,1\n";
  return s;
}

TEST(RunData, ParsesColumnsAndBundles) {
  auto csv = ParseRunCsv(Csv(true), "run.csv");
  ASSERT_TRUE(csv.ok()) << csv.error();
  EXPECT_EQ(csv->bundles, std::vector<std::string>{"b"});
  EXPECT_EQ(csv->At("b.true_on"), (std::vector<double>{0, 3, 5}));
  EXPECT_TRUE(std::isnan(csv->At("b.estimated_on")[0]));
}

TEST(RunFigures, BandIsEstimatePlusMinusTwoSd) {
  auto csv = ParseRunCsv(Csv(true), "run.csv");
  ASSERT_TRUE(csv.ok());
  const Axes a = CountAxes(*csv);
  ASSERT_EQ(a.bands.size(), 1u);
  // Rows 1 and 2 of the text: 2.5 +- 2 x 0.5 and 4.75 +- 2 x 0.25; row 0 has no estimate.
  EXPECT_TRUE(std::isnan(a.bands[0].lo[0]));
  EXPECT_DOUBLE_EQ(a.bands[0].lo[1], 1.5);
  EXPECT_DOUBLE_EQ(a.bands[0].hi[1], 3.5);
  EXPECT_DOUBLE_EQ(a.bands[0].lo[2], 4.25);
  EXPECT_DOUBLE_EQ(a.bands[0].hi[2], 5.25);
  EXPECT_LT(a.bands[0].color.a, 0.5);  // translucent
}

TEST(RunFigures, TrueAndEstimatedCountsDifferInStyleAndColour) {
  auto csv = ParseRunCsv(Csv(true), "run.csv");
  ASSERT_TRUE(csv.ok());
  const Axes a = CountAxes(*csv);
  ASSERT_EQ(a.series.size(), 2u);
  const Series &truth = a.series[0], &est = a.series[1];
  EXPECT_EQ(truth.style, LineStyle::kSolid);
  EXPECT_EQ(est.style, LineStyle::kDashed);
  const double dc = std::abs(truth.color.r - est.color.r) + std::abs(truth.color.g - est.color.g) +
                    std::abs(truth.color.b - est.color.b);
  EXPECT_GT(dc, 0.5);
}

TEST(RunFigures, NoBandWhenTheStdIsEmptyOrAbsent) {
  auto empty = ParseRunCsv(Csv(false), "run.csv");
  ASSERT_TRUE(empty.ok()) << empty.error();
  EXPECT_TRUE(CountAxes(*empty).bands.empty());
  // A CSV from before the column existed.
  std::string old = Csv(true);
  std::string out;
  std::istringstream in(old);
  for (std::string line; std::getline(in, line);) {
    // drop the 9th cell (b.estimated_on_std)
    std::vector<std::string> cells;
    std::stringstream ls(line);
    for (std::string c; std::getline(ls, c, ',');) cells.push_back(c);
    if (line.back() == ',') cells.emplace_back();
    cells.erase(cells.begin() + 8);
    for (size_t i = 0; i < cells.size(); ++i) out += (i ? "," : "") + cells[i];
    out += "\n";
  }
  auto legacy = ParseRunCsv(out, "old.csv");
  ASSERT_TRUE(legacy.ok()) << legacy.error();
  EXPECT_TRUE(CountAxes(*legacy).bands.empty());
  EXPECT_EQ(CountAxes(*legacy).series.size(), 2u);
}

TEST(RunFigures, TrackingPanelHoldsReferenceAndForce) {
  auto csv = ParseRunCsv(Csv(true), "run.csv");
  ASSERT_TRUE(csv.ok());
  const Axes a = TrackingAxes(*csv, IsAngleRun(*csv, RunInfo{}));
  EXPECT_EQ(a.y_label, "force (N)");
  ASSERT_EQ(a.series.size(), 2u);
  EXPECT_EQ(a.series[0].y, (std::vector<double>{0, 8, 8}));  // reference
  EXPECT_EQ(a.series[1].y, (std::vector<double>{0, 1, 2}));  // measured
  const auto figs = MakeRunFigures(*csv, RunInfo{"t", "kalman-augmented", "N", 0.5, 0.2, 1});
  ASSERT_EQ(figs.size(), 5u);
  EXPECT_EQ(figs[4].name, "all");
  EXPECT_EQ(figs[4].figure.panels.size(), 4u);
  EXPECT_EQ(figs[0].figure.title,
            "task t, estimator kalman-augmented, dT = 0.5 s, lambda = 0.2, seed 1");
}

TEST(RunFigures, AngleRunsAreShownInDegrees) {
  std::string s = kHeader;
  s += "0,0.5,0.25,0.25,0,0,0,1,,0.1,0,20,1\n1,0.5,0.5,0.5,0,0,0,1,,0.1,0,20,1\n";
  auto csv = ParseRunCsv(s, "arm.csv");
  ASSERT_TRUE(csv.ok()) << csv.error();
  ASSERT_TRUE(IsAngleRun(*csv, RunInfo{}));
  const Axes a = TrackingAxes(*csv, true);
  EXPECT_EQ(a.y_label, "joint angle (deg)");
  EXPECT_NEAR(a.series[0].y[0], 0.5 * 180 / M_PI, 1e-12);
  EXPECT_FALSE(IsAngleRun(*ParseRunCsv(Csv(true), "run.csv"), RunInfo{}));
}

struct BadCase {
  const char* what;
  std::string text;
  std::vector<std::string> expected;  // substrings of the message
};

TEST(RunData, BadCsvIsNamed) {
  std::string no_poff = kHeader;
  no_poff.replace(no_poff.find(",b.p_off"), 8, "");
  no_poff += "0,0,0,0,0,0,0,,,0.1,20,1\n";
  std::string nan_measured = kHeader;
  nan_measured += "0,0,,0,0,0,0,,,0.1,0,20,1\n1,0,nan,0,0,0,0,,,0.1,0,20,1\n";
  const std::vector<BadCase> cases = {
      {"empty", "", {"run.csv", "empty file"}},
      {"header only", kHeader, {"run.csv", "no data rows"}},
      {"missing column", no_poff, {"run.csv", "no column 'b.p_off'"}},
      {"NaN only", nan_measured, {"run.csv", "'measured'", "no finite value"}},
      {"not a number",
       std::string(kHeader) + "0,0,abc,0,0,0,0,,,0.1,0,20,1\n",
       {"run.csv line 2", "'measured'", "'abc'"}},
      {"short row", std::string(kHeader) + "0,0,0\n", {"run.csv line 2", "3 cells", "13"}},
      {"no bundle", "time,reference,measured\n0,0,0\n", {"run.csv", "true_on"}},
  };
  for (const auto& c : cases) {
    auto r = ParseRunCsv(c.text, "run.csv");
    ASSERT_FALSE(r.ok()) << c.what;
    for (const auto& e : c.expected)
      EXPECT_NE(r.error().find(e), std::string::npos) << c.what << ": " << r.error();
  }
}

}  // namespace file_run_data_test
}  // namespace recruit::plot
