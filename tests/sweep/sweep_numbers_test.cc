// The sweep's tables write numbers as the shortest text that reads back as the same double
// (table.csv: every number; table.md and report.md: the grid coordinates), and the report links
// and embeds the stability map the sweep draws.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "common/atomic_file.h"
#include "plot/plot_run.h"
#include "plot/render.h"
#include "sweep/grid.h"
#include "sweep/sweep_report.h"
#include "sweep/table.h"

namespace recruit::sweep {
namespace file_sweep_numbers_test {

namespace fs = std::filesystem;
using namespace ::recruit::sim;  // NOLINT: tasks and runs the sweeps are made of

fs::path FreshDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("recruit_sweep_numbers_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::vector<std::string> Split(const std::string& line, char sep) {
  std::vector<std::string> out;
  std::stringstream in(line);
  std::string field;
  while (std::getline(in, field, sep)) out.push_back(field);
  return out;
}

// The whole text must be one number (strtod consumes all of it).
double Parse(const std::string& text) {
  char* end = nullptr;
  const double x = std::strtod(text.c_str(), &end);
  EXPECT_TRUE(!text.empty() && *end == '\0') << "not a number: '" << text << "'";
  return x;
}

// Equal as doubles, NaN equal to NaN.
bool Same(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

// A cell of numbers whose %.6g text does not read back (and 0.29, %.17g "0.28999999999999998"),
// a subnormal and a NaN mean.
CellStats Cell(double dT, double lambda, std::vector<std::pair<std::string, double>> plant) {
  CellStats c;
  c.plant_values = std::move(plant);
  c.dT = dT;
  c.lambda = lambda;
  c.estimator = "kalman";
  c.seeds = 3;
  const double awkward[] = {0.29,
                            1.0 / 3,
                            0.1 + 0.2,
                            1.2345678901234567e-7,
                            123456.78901234,
                            2.0 / 7,
                            1e300 / 7,
                            0.7,
                            5e-324,
                            0.1,
                            2.5,
                            0.123456789};
  for (size_t k = 0; k < kMetricCount; ++k) {
    c.mean[k] = awkward[k % std::size(awkward)] * (k + 1);
    c.sd[k] = awkward[(k + 5) % std::size(awkward)];
  }
  c.mean[MetricIndex(&RunMetrics::mean_nees)] = std::nan("");  // a NaN mean reads back as NaN
  c.margin = -(0.1 + 0.2) / 3;
  c.meets = false;
  c.seeds_meeting = 1;
  c.margin_se = 0.29;
  return c;
}

// Significant digits of a number's text (leading zeros and an integer's trailing zeros are not).
int SignificantDigits(const std::string& text) {
  std::string digits;
  for (char ch : text.substr(0, text.find_first_of("eE"))) {
    if (std::isdigit(static_cast<unsigned char>(ch))) digits += ch;
  }
  const size_t first = digits.find_first_not_of('0');
  if (first == std::string::npos) return 0;
  const size_t last = digits.find_last_not_of('0');
  return static_cast<int>(last - first + 1);
}

// The table's text is the shortest that reads back: with one significant digit fewer, x does
// not (strtod of %.{n-1}g).
void ExpectShortest(const std::string& text, double x) {
  const int n = SignificantDigits(text);
  if (n <= 1 || !std::isfinite(x)) return;
  const std::string shorter = fmt::format("{:.{}g}", x, n - 1);
  EXPECT_NE(std::strtod(shorter.c_str(), nullptr), x) << text << " could be " << shorter;
}

// Each row of table.csv, number for number, is the cell's doubles exactly; 0.29 reads "0.29".
TEST(SweepNumbers, TableCsvReadsBackAsTheExactDoubles) {
  std::vector<CellStats> cells = {
      Cell(0.1 + 0.2, 0.29, {{"current", 0.29}, {"N", 60}}),
      Cell(1.0 / 3, 0.2, {{"current", 1.0 / 7}, {"N", 120}}),
  };
  cells[1].plant = 1;
  const fs::path dir = FreshDir("csv");
  ASSERT_TRUE(WriteTables(cells, TrackingCriterion{}, dir.string(), "numbers").ok());
  std::stringstream csv(*ReadFile((dir / "table.csv").string()));
  std::string line;
  std::getline(csv, line);
  const std::vector<std::string> head = Split(line, ',');
  std::vector<std::string> want_head = {"plant", "current", "N"};
  for (const std::string& c : CellColumns()) want_head.push_back(c);
  ASSERT_EQ(head, want_head);
  for (const CellStats& c : cells) {
    ASSERT_TRUE(std::getline(csv, line));
    const std::vector<std::string> f = Split(line, ',');
    ASSERT_EQ(f.size(), head.size()) << line;
    std::vector<double> want = {c.plant_values[0].second, c.plant_values[1].second, c.dT, c.lambda};
    std::vector<std::string> got = {f[1], f[2], f[3], f[4]};
    const std::vector<double> metrics = CellMetricValues(c);
    for (size_t k = 0; k < metrics.size(); ++k) {
      want.push_back(metrics[k]);
      got.push_back(f[7 + k]);
    }
    want.push_back(c.margin);
    got.push_back(f.back());
    for (size_t k = 0; k < want.size(); ++k) {
      EXPECT_TRUE(Same(Parse(got[k]), want[k])) << "'" << got[k] << "' is not " << want[k];
      ExpectShortest(got[k], want[k]);
    }
  }
  // 0.29 is written as 0.29 (plant value of row 1 and its lambda).
  std::stringstream again(*ReadFile((dir / "table.csv").string()));
  std::getline(again, line);
  std::getline(again, line);
  const std::vector<std::string> row = Split(line, ',');
  EXPECT_EQ(row[1], "0.29");
  EXPECT_EQ(row[4], "0.29");
  EXPECT_EQ(row[3], "0.30000000000000004");  // 0.1 + 0.2 is not 0.3
  EXPECT_EQ(row[7], "0.29");                 // the first metric's mean, awkward[0]
  // table.md names the cells by the same shortest text.
  const std::string md = *ReadFile((dir / "table.md").string());
  EXPECT_NE(md.find("| 0 | 0.29 | 60 | 0.30000000000000004 | 0.29 | kalman |"), std::string::npos)
      << md;
  EXPECT_NE(md.find("| 1 | 0.14285714285714285 | 120 | 0.3333333333333333 | 0.2 |"),
            std::string::npos)
      << md;
  EXPECT_EQ(md.find("0.28999999999999998"), std::string::npos);
}

std::string Base64(const std::string& in) {  // RFC 4648, for the embedded map
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  unsigned v = 0;
  int bits = 0;
  for (unsigned char ch : in) {
    v = (v << 8) | ch;
    bits += 8;
    while (bits >= 6) {
      bits -= 6;
      out += k[(v >> bits) & 63];
    }
  }
  if (bits > 0) out += k[(v << (6 - bits)) & 63];
  while (out.size() % 4) out += '=';
  return out;
}

// Two dT of one estimator and lambda 0.29: the longer meets the criterion.
std::vector<CellStats> TwoCells(std::vector<std::pair<std::string, double>> plant) {
  std::vector<CellStats> cells = {Cell(0.25, 0.29, plant), Cell(0.1 + 0.2, 0.29, plant)};
  for (CellStats& c : cells) c.mean[MetricIndex(&RunMetrics::overshoot)] = 0.3;
  cells[1].meets = true;
  cells[1].margin = 0.05;
  cells[1].seeds_meeting = 3;
  cells[1].mean[MetricIndex(&RunMetrics::overshoot)] = 0.04;
  return cells;
}

// The sweep's own chain: table and stability.dat, the map drawn from it as `recruit sweep` does,
// then the report: report.md links stability.png and says how to read it, report.html embeds its
// bytes; the recommended row names lambda and dT by their shortest text.
TEST(SweepReportLinks, ReportLinksAndEmbedsTheStabilityMap) {
  const std::vector<CellStats> cells = TwoCells({});
  const fs::path dir = FreshDir("map");
  ASSERT_TRUE(WriteTables(cells, TrackingCriterion{}, dir.string(), "numbers").ok());
  ASSERT_TRUE(plot::RunPlot(sweep::StabilityMapOptions(dir.string(), "numbers", 1)).ok());
  const sweep::ReportInput in{"numbers", "a test", TrackingCriterion{}, cells, {}, {}, {}};
  ASSERT_TRUE(sweep::WriteReport(in, dir.string(), plot::RenderFigure).ok());
  const std::string md = *ReadFile((dir / "report.md").string());
  EXPECT_NE(md.find("](stability.png)"), std::string::npos) << md;
  EXPECT_NE(md.find("Stability map: one panel per estimator"), std::string::npos);
  EXPECT_NE(md.find("| kalman | 0.29 | 0.30000000000000004 |"), std::string::npos) << md;
  const std::string png = *ReadFile((dir / "stability.png").string());
  ASSERT_GT(png.size(), 100u);
  const std::string html = *ReadFile((dir / "report.html").string());
  EXPECT_NE(html.find("src=\"data:image/png;base64," + Base64(png) + "\""), std::string::npos);
}

// No map drawn: no link. With plant axes the sweep draws none, so a stale stability.png left in
// the folder is not linked either.
TEST(SweepReportLinks, NoStabilityMapNoLink) {
  const fs::path dir = FreshDir("nomap");
  const sweep::ReportInput bare{"numbers", "a test", TrackingCriterion{}, TwoCells({}), {}, {}, {}};
  ASSERT_TRUE(sweep::WriteReport(bare, dir.string(), plot::RenderFigure).ok());
  EXPECT_EQ(ReadFile((dir / "report.md").string())->find("stability.png"), std::string::npos);

  const fs::path axes = FreshDir("axes");
  ASSERT_TRUE(WriteFileAtomically((axes / "stability.png").string(), "stale").ok());
  const sweep::ReportInput in{
      "numbers", "a test", TrackingCriterion{}, TwoCells({{"current", 0.29}}), {}, {}, {}};
  ASSERT_TRUE(sweep::WriteReport(in, axes.string(), plot::RenderFigure).ok());
  const std::string md = *ReadFile((axes / "report.md").string());
  EXPECT_EQ(md.find("stability.png"), std::string::npos);
  EXPECT_NE(md.find("| 0 | 0.29 | kalman | 0.29 | 0.30000000000000004 |"), std::string::npos) << md;
}

}  // namespace file_sweep_numbers_test
}  // namespace recruit::sweep
