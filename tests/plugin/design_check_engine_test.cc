// The design check as a MuJoCo program sees it (issue 25 item 8, issue 26 item 3): a bundle
// outside NiTi's domain makes the compiler fail naming actuator, key and value; one past a
// long-life limit loads with one warning naming the actuator, limit, value and a current that
// meets it; the shipped models load without a design warning.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <string>

#include "plugin/bundle_config.h"
#include "plugin/design_limits.h"
#include "tests/plugin/mujoco_util.h"

namespace recruit::sma {
namespace file_design_check_engine_test {

using testing::Bench;
using testing::BenchXml;
using testing::ConfigXml;
using ::testing::HasSubstr;
using testing::Load;
using testing::WarningCapture;

TEST(DesignCheck, OutOfDomainConfigFailsToCompileNamingActuatorKeyAndValue) {
  const struct {
    std::string key, value, expected;
  } cases[] = {{"current", "100", "above 300 C"},
               {"wire_diameter", "1e-9", "above 300 C"},
               {"prestretch", "10", "814 MPa"},
               {"ambient", "-100", "never contracts"},
               {"coil_diameter", "0.05e-3", "must exceed the wire"},
               {"wire_length", "1e-300", "shorter than 20 wire diameters"}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.key);
    Bench b;
    b.config = ConfigXml(c.key, c.value);
    b.name = "biceps";
    WarningCapture refusal;  // init's error is a warning too: kept out of MUJOCO_LOG.TXT
    auto m = Load(BenchXml(b));
    ASSERT_FALSE(m.ok());
    EXPECT_THAT(m.error(),
                HasSubstr("recruit.sma actuator 'biceps': config " + c.key + "=" + c.value + ":"));
    EXPECT_THAT(m.error(), HasSubstr(c.expected));
  }
}

TEST(DesignCheck, HotWireLoadsWithOneWarningNamingLimitValueAndCurrent) {
  Bench b;
  b.config = ConfigXml("wire_diameter", "0.15e-3") + ConfigXml("current", "0.40") +
             ConfigXml("units", "7");  // a model of its own (the check runs once per model)
  b.name = "hot";
  WarningCapture warnings;
  auto m = Load(BenchXml(b));
  ASSERT_TRUE(m.ok()) << m.error();
  int design = 0;
  for (const std::string& t : warnings.texts()) {
    if (t.find("long-life") != std::string::npos) {
      ++design;
      EXPECT_THAT(t, HasSubstr("recruit.sma actuator 'hot': steady 21"));
      EXPECT_THAT(t, HasSubstr("above the long-life 120 C: current=0.289"));
    }
  }
  EXPECT_EQ(design, 1) << warnings.joined();
  // The same text the MuJoCo-free function gives the lead's run summaries.
  auto c = BundleConfig::FromText("hot", "wire_diameter=0.15e-3 current=0.40 units=7");
  ASSERT_TRUE(c.ok()) << c.error();
  EXPECT_THAT(warnings.joined(), HasSubstr("recruit.sma " + DesignWarning(*c)));
}

TEST(DesignCheck, ShippedModelsLoadWithoutDesignWarnings) {
  for (const char* model : {"isometric_bench.xml", "elbow_arm.xml", "isometric_bench_muscle.xml",
                            "elbow_arm_muscle.xml"}) {
    SCOPED_TRACE(model);
    testing::LoadPluginLibrary();
    WarningCapture warnings;
    char err[1000] = "";
    mjModel* m = mj_loadXML((std::string(RECRUIT_SOURCE_DIR "/models/") + model).c_str(), nullptr,
                            err, sizeof err);
    ASSERT_NE(m, nullptr) << err;
    EXPECT_EQ(warnings.joined().find("long-life"), std::string::npos) << warnings.joined();
    EXPECT_EQ(warnings.joined().find("Dynalloy"), std::string::npos) << warnings.joined();
    mj_deleteModel(m);
  }
}

}  // namespace file_design_check_engine_test
}  // namespace recruit::sma
