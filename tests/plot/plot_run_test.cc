// `recruit plot`'s work (RunPlot): what it writes on good input, and on bad input (options,
// files) a message naming the option or file and the value, and nothing written.
#include "plot/plot_run.h"

#include <gtest/gtest.h>
#include <lodepng.h>

#include <filesystem>
#include <fstream>

#include "common/atomic_file.h"

namespace recruit::plot {
namespace file_plot_run_test {

namespace fs = std::filesystem;

const std::string kTiny = std::string(RECRUIT_SOURCE_DIR) + "/tests/plot/data/tiny_steps.csv";

std::string FreshDir(const std::string& name) {
  const fs::path p = fs::path(::testing::TempDir()) / ("recruit_plot_" + name);
  fs::remove_all(p);
  return p.string();
}

std::string WriteText(const std::string& name, const std::string& text) {
  const std::string path = (fs::path(::testing::TempDir()) / name).string();
  std::ofstream(path) << text;
  return path;
}

TEST(PlotRun, WritesEveryFigureInEveryFormat) {
  PlotOptions o;
  o.csv = kTiny;
  o.out_dir = FreshDir("good");
  o.formats = "png,svg";
  o.width = 640, o.height = 400;
  auto written = RunPlot(o);
  ASSERT_TRUE(written.ok()) << written.error();
  EXPECT_EQ(written->size(), 10u);
  for (const char* fig : {"tracking", "count", "broadcast", "temperature", "all"}) {
    const std::string png = o.out_dir + "/tiny_" + fig + ".png";
    std::vector<unsigned char> rgba;
    unsigned w = 0, h = 0;
    ASSERT_EQ(lodepng::decode(rgba, w, h, png), 0u) << png;
    EXPECT_EQ(w, 640u);
    EXPECT_EQ(h, std::string(fig) == "all" ? 880u : 400u);
    EXPECT_TRUE(fs::file_size(o.out_dir + "/tiny_" + fig + ".svg") > 0);
  }
  // Only the ten figures: no temporary files left behind.
  EXPECT_EQ(std::distance(fs::directory_iterator(o.out_dir), fs::directory_iterator()), 10);
}

struct BadCase {
  const char* what;
  PlotOptions options;
  std::vector<std::string> expected;
};

TEST(PlotRun, BadInputIsNamedAndWritesNothing) {
  const std::string empty = WriteText("plot_empty.csv", "");
  const std::string header_only = WriteText(
      "plot_header.csv",
      "time,reference,measured,b.true_on,b.estimated_on,b.p_on,b.p_off\n0,0,0,0,,0.1,0\n");
  const std::string bad_json = WriteText("plot_bad.json", "{\"task\": ");
  const std::string bad_unit = WriteText("plot_unit.json", "{\"unit\": \"furlong\"}");
  const std::string out = FreshDir("bad");
  auto opts = [&](auto edit) {
    PlotOptions o;
    o.csv = kTiny;
    o.out_dir = out;
    edit(o);
    return o;
  };
  const std::vector<BadCase> cases = {
      {"width too small",
       opts([](PlotOptions& o) { o.width = 50; }),
       {"--width", "50 px", "240..8192"}},
      {"height too big", opts([](PlotOptions& o) { o.height = 100000; }), {"--height", "100000"}},
      {"format", opts([](PlotOptions& o) { o.formats = "png,jpg"; }), {"--format", "'jpg'", "svg"}},
      {"missing csv",
       opts([](PlotOptions& o) { o.csv = "/nonexistent/run_steps.csv"; }),
       {"/nonexistent/run_steps.csv"}},
      {"empty csv", opts([&](PlotOptions& o) { o.csv = empty; }), {empty, "empty file"}},
      {"missing columns",
       opts([&](PlotOptions& o) { o.csv = header_only; }),
       {header_only, "no column 'b.force'"}},
      {"bad summary", opts([&](PlotOptions& o) { o.summary = bad_json; }), {bad_json, "JSON"}},
      {"bad unit",
       opts([&](PlotOptions& o) { o.summary = bad_unit; }),
       {bad_unit, "'unit'", "furlong"}},
  };
  for (const auto& c : cases) {
    auto r = RunPlot(c.options);
    ASSERT_FALSE(r.ok()) << c.what;
    for (const auto& e : c.expected) {
      EXPECT_NE(r.error().find(e), std::string::npos) << c.what << ": " << r.error();
    }
    EXPECT_FALSE(fs::exists(out)) << c.what << " wrote " << out;
  }
}

}  // namespace file_plot_run_test
}  // namespace recruit::plot
