// Parsing and validation of recruit.sma.* texts: every bad input gives a message naming the
// actuator and the key, never a crash.
#include "plugin/bundle_config.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace recruit::sma {
namespace file_bundle_config_test {

using ::testing::HasSubstr;

TEST(BundleConfig, ParsesEveryKindOfKey) {
  auto c = BundleConfig::FromText(
      "biceps",
      "units=120 law=wire wire_diameter=0.15e-3 wire_length=0.08 prestrain=0.02 "
      "current=0.3 ambient=25 h=90 latent_heat=0 As=70 Af=80 Ms=50 Mf=40 "
      "C_A=8e6 C_M=9e6 E_A=70e9 E_M=30e9 eps_L=0.035 merge_temperature=0.01");
  ASSERT_TRUE(c.ok()) << c.error();
  EXPECT_EQ(c->actuator, "biceps");
  EXPECT_EQ(c->units, 120);
  EXPECT_EQ(c->unit.law, ForceLaw::kWire);
  EXPECT_DOUBLE_EQ(c->unit.prestretch, 0.02 * 0.08);
  EXPECT_DOUBLE_EQ(c->unit.current, 0.3);
  EXPECT_DOUBLE_EQ(c->unit.h, 90);
  EXPECT_DOUBLE_EQ(c->unit.C_M, 9e6);
  EXPECT_DOUBLE_EQ(c->merge_temperature, 0.01);
}

TEST(BundleConfig, EmptyTextGivesCalibratedDefaults) {
  auto c = BundleConfig::FromText("m", "");
  ASSERT_TRUE(c.ok()) << c.error();
  EXPECT_EQ(c->units, 60);
  EXPECT_EQ(c->unit.law, ForceLaw::kWire);
  EXPECT_EQ(c->unit.series, 1);
  EXPECT_EQ(c->unit.parallel, 1);
  EXPECT_DOUBLE_EQ(c->unit.series_spring, 114);
}

TEST(BundleConfig, ParsesSeriesParallelAndCouplingSpring) {
  auto c = BundleConfig::FromText("biceps", "series=3 parallel=2 series_spring=0");
  ASSERT_TRUE(c.ok()) << c.error();
  EXPECT_EQ(c->unit.series, 3);
  EXPECT_EQ(c->unit.parallel, 2);
  EXPECT_EQ(c->unit.series_spring, 0.0);
  // prestrain strains every segment alike: the unit's prestretch is series times a wire's.
  auto w = BundleConfig::FromText("b", "law=wire series=2 wire_length=0.05 prestrain=0.03");
  ASSERT_TRUE(w.ok()) << w.error();
  EXPECT_DOUBLE_EQ(w->unit.prestretch, 2 * 0.05 * 0.03);
}

struct BadCase {
  const char* text;
  const char* expected;  // substring of the error
};

class BundleConfigRejects : public ::testing::TestWithParam<BadCase> {};

TEST_P(BundleConfigRejects, WithMessageNamingActuatorAndKey) {
  auto c = BundleConfig::FromText("triceps", GetParam().text);
  ASSERT_FALSE(c.ok()) << GetParam().text;
  EXPECT_THAT(c.error(), HasSubstr("actuator 'triceps'"));
  EXPECT_THAT(c.error(), HasSubstr(GetParam().expected));
}

INSTANTIATE_TEST_SUITE_P(
    AllFields, BundleConfigRejects,
    ::testing::Values(
        BadCase{"curent=0.2", "unknown key 'curent' (allowed: law, units,"},
        BadCase{"units", "'units' is not key=value"}, BadCase{"units=", "units= has no value"},
        BadCase{"=3", "'=3' is not key=value"},
        BadCase{"units=0", "units=0 is out of range: must be in [1, 1e+06]"},
        BadCase{"units=2.5", "units=2.5 must be a whole number"},
        BadCase{"current=abc", "current=abc is not a finite number"},
        BadCase{"current=nan", "current=nan is not a finite number"},
        BadCase{"current=inf", "current=inf is not a finite number"},
        BadCase{"current=0.2x", "current=0.2x is not a finite number"},
        BadCase{"current=-1", "current=-1 is out of range: must be in [0, 100] A"},
        BadCase{"wire_diameter=0", "wire_diameter=0 is out of range: must be in (0"},
        BadCase{"density=-5", "density=-5 is out of range"},
        BadCase{"eps_L=0.5", "eps_L=0.5 is out of range"},
        BadCase{"emissivity=2", "emissivity=2 is out of range: must be in [0, 1]"},
        BadCase{"law=rope", "law=rope is invalid: allowed values are wire, spring"},
        BadCase{"current=0.2 current=0.3", "key 'current' given twice"},
        BadCase{"law=spring prestrain=0.01", "prestrain is for law=wire"},
        BadCase{"law=wire prestrain=0.01 prestretch=0.001", "not both"},
        BadCase{"Ms=45 Mf=50", "Mf=50 must be below Ms=45"},
        BadCase{"As=80 Af=70", "As=80 must be below Af=70"},
        BadCase{"law=spring coil_diameter=0.05e-3", "coil_diameter=5e-05 must exceed"},
        BadCase{"C_A=0", "C_A=0 is out of range"},
        BadCase{"merge_xi=-1", "merge_xi=-1 is out of range"},
        BadCase{"series=0", "series=0 is out of range: must be in [1, 1000]"},
        BadCase{"parallel=0", "parallel=0 is out of range: must be in [1, 1000]"},
        BadCase{"series=1.5", "series=1.5 must be a whole number"},
        BadCase{"parallel=2.25", "parallel=2.25 must be a whole number"},
        BadCase{"series=two", "series=two is not a finite number"},
        BadCase{"parallel=5000", "parallel=5000 is out of range"},
        BadCase{"series_spring=-3", "series_spring=-3 is out of range: must be in [0"},
        BadCase{"unit_model=tabulated",
                "unit_model=tabulated is invalid: allowed values are "
                "exact, binned"},
        BadCase{"unit_model=binned bins=1", "bins=1 is out of range: must be in [2, 1e+06]"},
        BadCase{"unit_model=binned bins=12.5", "bins=12.5 must be a whole number"},
        BadCase{"bins=16", "bins=16 is for unit_model=binned"},
        BadCase{"unit_model=exact bins=16", "bins=16 is for unit_model=binned"}));

TEST(BundleConfig, UnitModelDefaultsToExact) {
  auto c = BundleConfig::FromText("m", "");
  ASSERT_TRUE(c.ok()) << c.error();
  EXPECT_EQ(c->unit_model, UnitModelKind::kExact);
  auto b = BundleConfig::FromText("m", "unit_model=binned");
  ASSERT_TRUE(b.ok()) << b.error();
  EXPECT_EQ(b->unit_model, UnitModelKind::kBinned);
  EXPECT_EQ(b->bins, 16);
  auto n = BundleConfig::FromText("m", "bins=40 unit_model=binned");
  ASSERT_TRUE(n.ok()) << n.error();
  EXPECT_EQ(n->bins, 40);
}

TEST(BundleConfig, EveryNumericKeyRejectsNonFiniteAndOutOfRangeValues) {
  for (const std::string& key : BundleConfig::Keys()) {
    if (key == "law") continue;
    for (const char* bad : {"nan", "-inf", "1e300", "-1e300", "x"}) {
      auto c = BundleConfig::FromText("a", key + "=" + bad);
      ASSERT_FALSE(c.ok()) << key << "=" << bad;
      EXPECT_THAT(c.error(), HasSubstr("actuator 'a'"));
      EXPECT_THAT(c.error(), HasSubstr(key + "=" + bad)) << c.error();
    }
  }
}

TEST(BundleConfig, KeysListsEveryDocumentedKey) {
  const auto keys = BundleConfig::Keys();
  for (const char* k : {"law",           "units",
                        "wire_diameter", "coil_diameter",
                        "turns",         "prestretch",
                        "prestrain",     "current",
                        "ambient",       "h",
                        "latent_heat",   "As",
                        "C_A",           "E_A",
                        "G_A",           "eps_L",
                        "ref_length",    "merge_temperature",
                        "series",        "parallel",
                        "series_spring", "unit_model",
                        "bins"}) {
    EXPECT_NE(std::find(keys.begin(), keys.end(), k), keys.end()) << k;
  }
}

}  // namespace file_bundle_config_test
}  // namespace recruit::sma
