// Column mode of `recruit plot` (--panel): spec parsing, the figure's series against the table's
// columns times their scale, errors that name the column and list the table's, and RunPlot
// writing one file per format from a table that is not a `recruit simulate` run.
#include "plot/column_figure.h"

#include <gtest/gtest.h>
#include <lodepng.h>

#include <filesystem>
#include <fstream>

#include "plot/plot_run.h"
#include "plot/stability_map.h"

namespace recruit::plot {
namespace file_column_figure_test {

namespace fs = std::filesystem;

const char* kTable =
    "time,tension,on,mean_temperature\n"
    "0,0,0,20\n"
    "1,5.5,60,40\n"
    "2,26.5,60,70\n";

TEST(ColumnFigure, ParsesSpecsAndRefusesMalformedOnes) {
  auto p = ParsePanelSpec("force (N)=tension, on*0.5");
  ASSERT_TRUE(p.ok()) << p.error();
  EXPECT_EQ(p->y_label, "force (N)");
  ASSERT_EQ(p->columns.size(), 2u);
  EXPECT_EQ(p->columns[0].column, "tension");
  EXPECT_EQ(p->columns[0].scale, 1);
  EXPECT_EQ(p->columns[1].column, "on");
  EXPECT_EQ(p->columns[1].scale, 0.5);
  for (const char* bad : {"tension", "=tension", "force (N)=", "f=on*x", "f=on*0", "f=a,,b"}) {
    auto r = ParsePanelSpec(bad);
    EXPECT_FALSE(r.ok()) << bad;
    if (!r.ok()) {
      EXPECT_NE(r.error().find("--panel"), std::string::npos) << r.error();
    }
  }
}

TEST(ColumnFigure, SeriesAreTheColumnsTimesTheirScale) {
  auto table = ParseCsvTable(kTable, "t.csv");
  ASSERT_TRUE(table.ok()) << table.error();
  auto spec = ParsePanelSpec("force (N)=tension,on*0.5");
  auto temp = ParsePanelSpec("temperature (C)=mean_temperature");
  auto fig = MakeColumnFigure(*table, "time", "time (s)", {*spec, *temp}, "Fig. 4");
  ASSERT_TRUE(fig.ok()) << fig.error();
  ASSERT_EQ(fig->panels.size(), 2u);
  const Axes& a = fig->panels[0];
  ASSERT_EQ(a.series.size(), 2u);
  EXPECT_EQ(a.series[1].label, "on x 0.5");
  EXPECT_EQ(a.series[0].y, (std::vector<double>{0, 5.5, 26.5}));
  EXPECT_EQ(a.series[1].y, (std::vector<double>{0, 30, 30}));
  EXPECT_EQ(a.series[1].x, (std::vector<double>{0, 1, 2}));
  EXPECT_EQ(fig->panels[1].y_label, "temperature (C)");
  EXPECT_EQ(fig->title, "Fig. 4");
  // Two series in one panel are told apart by colour.
  EXPECT_FALSE(a.series[0].color.r == a.series[1].color.r &&
               a.series[0].color.b == a.series[1].color.b);
}

TEST(ColumnFigure, UnknownColumnsAreNamedWithTheTablesColumns) {
  auto table = ParseCsvTable(kTable, "t.csv");
  ASSERT_TRUE(table.ok());
  auto spec = ParsePanelSpec("f=force");
  auto fig = MakeColumnFigure(*table, "time", "time (s)", {*spec}, "");
  ASSERT_FALSE(fig.ok());
  EXPECT_NE(fig.error().find("no column 'force'"), std::string::npos) << fig.error();
  EXPECT_NE(fig.error().find("time, tension, on, mean_temperature"), std::string::npos);
  auto nox = MakeColumnFigure(*table, "t", "t", {*ParsePanelSpec("f=on")}, "");
  ASSERT_FALSE(nox.ok());
  EXPECT_NE(nox.error().find("no column 't' for x"), std::string::npos) << nox.error();
}

TEST(ColumnFigure, RunPlotWritesOneFilePerFormat) {
  const fs::path dir = fs::path(::testing::TempDir()) / "recruit_plot_columns";
  fs::remove_all(dir);
  const std::string csv = (fs::path(::testing::TempDir()) / "fig4_table.csv").string();
  std::ofstream(csv) << kTable;
  PlotOptions o;
  o.csv = csv;
  o.out_dir = dir.string();
  o.name = "fig4";
  o.formats = "png,svg";
  o.width = 640, o.height = 400;
  o.panels = {"force (N)=tension,on*0.5", "temperature (C)=mean_temperature"};
  auto written = RunPlot(o);
  ASSERT_TRUE(written.ok()) << written.error();
  ASSERT_EQ(written->size(), 2u);
  EXPECT_EQ((*written)[0], (dir / "fig4.png").string());
  unsigned w = 0, h = 0;
  std::vector<unsigned char> rgba;
  ASSERT_EQ(lodepng::decode(rgba, w, h, (dir / "fig4.png").string()), 0u);
  EXPECT_EQ(w, 640u);
  EXPECT_EQ(h, static_cast<unsigned>(0.55 * 2 * 400));  // 0.55 x height per panel
  // A run CSV's required columns are not asked for in column mode; a bad spec writes nothing.
  o.panels = {"bad"};
  fs::remove_all(dir);
  EXPECT_FALSE(RunPlot(o).ok());
  EXPECT_FALSE(fs::exists(dir));
}

TEST(PlotRunFigure, OnlyTheChosenFigureIsWrittenUnderTheGivenName) {
  const fs::path dir = fs::path(::testing::TempDir()) / "recruit_plot_one";
  fs::remove_all(dir);
  PlotOptions o;
  o.csv = std::string(RECRUIT_SOURCE_DIR) + "/tests/plot/data/tiny_steps.csv";
  o.out_dir = dir.string();
  o.name = "repro_fig9";
  o.figure = "all";
  auto written = RunPlot(o);
  ASSERT_TRUE(written.ok()) << written.error();
  ASSERT_EQ(written->size(), 1u);
  EXPECT_EQ((*written)[0], (dir / "repro_fig9.png").string());
  o.figure = "nope";
  auto bad = RunPlot(o);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().find("--figure: 'nope'"), std::string::npos) << bad.error();
  EXPECT_NE(bad.error().find("tracking"), std::string::npos) << bad.error();
}

// The stability map of a sweep: stability.dat parsed into panels and cells; the colour scale's
// anchors; the map's cell colours where the cells are; a malformed row named.
TEST(StabilityMap, ParsesSweepsDatAndColoursEachCellByItsOvershoot) {
  const std::string dat =
      "# estimator output\n# dT lambda overshoot_percent meets\n"
      "0.5 0.1 0.0000 1\n2 0.1 60.0000 0\n0.5 0.5 10.0000 0\n2 0.5 30.0000 0\n\n\n"
      "# estimator kalman2\n# dT lambda overshoot_percent meets\n0.5 0.2 5.0 1\n\n\n";
  auto panels = ParseStabilityDat(dat, "s.dat");
  ASSERT_TRUE(panels.ok()) << panels.error();
  ASSERT_EQ(panels->size(), 2u);
  EXPECT_EQ((*panels)[0].estimator, "output");
  ASSERT_EQ((*panels)[0].cells.size(), 4u);
  EXPECT_EQ((*panels)[0].cells[1].dT, 2);
  EXPECT_EQ((*panels)[0].cells[1].overshoot_percent, 60);
  EXPECT_TRUE((*panels)[0].cells[0].meets);
  const Color g = OvershootColor(0), y = OvershootColor(10), r = OvershootColor(50);
  EXPECT_GT(g.g, g.r);  // green
  EXPECT_GT(y.r, 0.9);  // yellow
  EXPECT_GT(y.g, 0.8);
  EXPECT_GT(r.r, 0.8);  // red
  EXPECT_LT(r.g, 0.2);
  EXPECT_EQ(OvershootColor(80).r, r.r);  // clamped at 50 %
  // Rendered: one panel's 2 x 2 grid. The centre of the lower-left quarter of the first
  // panel's data area is the (0.5, 0.1) cell: its ring (black) or fill (green) dominates.
  auto png = RenderStabilityMap({(*panels)[0]}, "t", 600, 400, Format::kPng);
  ASSERT_TRUE(png.ok()) << png.error();
  std::vector<unsigned char> rgba;
  unsigned w = 0, h = 0;
  ASSERT_EQ(
      lodepng::decode(rgba, w, h, reinterpret_cast<const unsigned char*>(png->data()), png->size()),
      0u);
  ASSERT_EQ(w, 600u);
  // Count red-dominated pixels: the 60 % and 30 % cells exist, so some are red/orange.
  int red = 0, green = 0;
  for (size_t i = 0; i + 3 < rgba.size(); i += 4) {
    red += rgba[i] > 180 && rgba[i + 1] < 60;
    green += rgba[i + 1] > 120 && rgba[i] < 60;
  }
  EXPECT_GT(red, 1000);
  EXPECT_GT(green, 1000);
  auto bad = ParseStabilityDat("# estimator x\n0.5 0.1 abc 1\n", "s.dat");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().find("s.dat line 2"), std::string::npos) << bad.error();
  EXPECT_FALSE(ParseStabilityDat("", "s.dat").ok());
}

}  // namespace file_column_figure_test
}  // namespace recruit::plot
