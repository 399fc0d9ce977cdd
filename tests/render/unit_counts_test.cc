// The working/open/stuck units a render shows (render/unit_counts.h), read from the plugin's
// truth sensor, against the host API's own count (SmaHost::Failures), with the run's sensors off
// as sim::Plant has them (the reader then evaluates them on its own copy and leaves the run's
// data alone); a bundle without failure keys has none.
#include "render/unit_counts.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <vector>

#include "common/mujoco_load.h"
#include "plugin/sma_host.h"
#include "render/telemetry_plots.h"

namespace recruit::render {
namespace file_unit_counts_test {

std::string Bench(const std::string& config) {
  std::ifstream in(RECRUIT_SOURCE_DIR "/models/isometric_bench.xml");
  std::stringstream buf;
  buf << in.rdbuf();
  std::string xml = buf.str();
  const std::string anchor = "<instance name=\"bundle_units\">";
  xml.insert(xml.find(anchor) + anchor.size(), config);
  return xml;
}

TelemetrySample OneBundle() {
  TelemetrySample s;
  s.bundles.resize(1);
  s.bundles[0].actuator = "bundle";
  return s;
}

TEST(UnitCounts, ReadFromTheTruthSensorAsTheHostCountsThem) {
  for (const bool sensors_off : {true, false}) {
    auto model =
        LoadModelFromString(Bench(R"(<config key="failures" value="0.2:6:open,0.4:2:stuck"/>)"));
    ASSERT_TRUE(model.ok()) << model.error();
    mjModel* m = model->get();
    if (sensors_off) m->opt.disableflags |= mjDSBL_SENSOR;
    auto host = sma::SmaHost::Create(m);
    ASSERT_TRUE(host.ok());
    DataPtr d(mj_makeData(m));
    (*host)->Reset(d.get(), 7);
    ASSERT_TRUE((*host)->Broadcast(d.get(), 0, 0.5, 0).ok());
    UnitCountReader reader;
    for (int step = 0; d->time < 0.6; ++step) {
      mj_step(m, d.get());
      if (step % 25 != 24) continue;
      const std::vector<mjtNum> qpos(d->qpos, d->qpos + m->nq);
      const double time = d->time;
      const auto counts = reader.Read(m, d.get(), OneBundle());
      ASSERT_EQ(counts.size(), 1u);
      ASSERT_TRUE(counts[0].has_value());
      const auto truth = (*host)->Failures(d.get(), 0);
      EXPECT_EQ(counts[0]->working, truth.working) << d->time;
      EXPECT_EQ(counts[0]->open, truth.open);
      EXPECT_EQ(counts[0]->stuck, truth.stuck);
      EXPECT_EQ(counts[0]->total(), 60);
      EXPECT_EQ(time, d->time);  // the run's data is left as it was
      EXPECT_EQ(qpos, std::vector<mjtNum>(d->qpos, d->qpos + m->nq));
    }
    const auto last = reader.Read(m, d.get(), OneBundle());
    EXPECT_EQ(last[0]->open, 6);
    EXPECT_EQ(last[0]->stuck, 2);
    EXPECT_EQ(WorkingText(*last[0]), "52 of 60 working (6 open, 2 stuck)");
  }
}

TEST(UnitCounts, NoneWithoutFailureKeys) {
  auto model = LoadModelFromString(Bench(""));
  ASSERT_TRUE(model.ok());
  DataPtr d(mj_makeData(model->get()));
  mj_forward(model->get(), d.get());
  UnitCountReader reader;
  const auto counts = reader.Read(model->get(), d.get(), OneBundle());
  ASSERT_EQ(counts.size(), 1u);
  EXPECT_FALSE(counts[0].has_value());
}

// The units panel draws the working units of a bundle that has counts, and nothing more for one
// without (the plots stay as they were).
TEST(UnitCounts, UnitsPanelShowsWorkingAgainstTotal) {
  TelemetryPlots with(20), without(20);
  for (int k = 0; k < 10; ++k) {
    TelemetrySample s = OneBundle();
    s.time = k;
    s.bundles[0].true_on = 10;
    const UnitCounts c{k < 5 ? 60 : 54, k < 5 ? 0 : 6, 0};
    with.Add(s, {c});
    without.Add(s);
  }
  const auto& lines = with.lines(with.num_panels() - 1);
  ASSERT_EQ(lines.size(), without.lines(without.num_panels() - 1).size() + 1);
  EXPECT_EQ(lines.back().name, "working");
  EXPECT_EQ(lines.back().y.front(), 60);
  EXPECT_EQ(lines.back().y.back(), 54);
  EXPECT_EQ(lines.back().style, LineStyle::kStairs);
}

}  // namespace file_unit_counts_test
}  // namespace recruit::render
