// Plant records: the hash is FNV-1a 64 of the unit's canonical JSON (checked against the value
// computed by hand in Python), the bench's and the arm's bundles get different records, the
// shipped bench models match the bench, and a model identified on another plant is refused by
// the estimator factory with both plants named.
#include "identification/plant_record.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cstdio>
#include <fstream>

#include "common/mujoco_ptr.h"
#include "control/on_count_estimator.h"

namespace recruit::identification {
namespace file_plant_record_test {

using namespace ::recruit::control;  // NOLINT: the controller side these tests check against

// FNV-1a 64 of the text {"a":1}, by the published algorithm (offset 0xcbf29ce484222325, prime
// 0x100000001b3), computed independently in Python.
TEST(PlantRecord, HashIsFnv1aOfTheCanonicalJson) {
  EXPECT_EQ(PlantHash(nlohmann::json{{"a", 1}}), "9c3e82dd6fcae8b1");
  EXPECT_NE(PlantHash(nlohmann::json{{"a", 1}}), PlantHash(nlohmann::json{{"a", 2}}));
}

nlohmann::json Record(const std::string& model, const std::string& actuator) {
  char err[1000] = "";
  ModelPtr m(mj_loadXML(model.c_str(), nullptr, err, sizeof err));
  EXPECT_TRUE(m) << err;
  auto host = sma::SmaHost::Create(m.get());
  EXPECT_TRUE(host.ok());
  const int b = (*host)->BundleIndex(actuator);
  EXPECT_GE(b, 0);
  return PlantRecord(**host, b, model);
}

TEST(PlantRecord, BenchAndArmBundlesDifferAndTheShippedModelsMatchTheBench) {
  const nlohmann::json bench = Record(RECRUIT_SOURCE_DIR "/models/isometric_bench.xml", "bundle");
  const nlohmann::json flexor = Record(RECRUIT_SOURCE_DIR "/models/elbow_arm.xml", "flexor");
  EXPECT_EQ(bench["num_units"], 60);
  EXPECT_EQ(bench["unit"]["series"], 1);
  EXPECT_EQ(flexor["unit"]["series"], 6);
  EXPECT_NE(bench["hash"], flexor["hash"]);
  for (const char* f : {"/models/identified/bench_n60_dt0.5_m20.json",
                        "/models/identified/bench_n60_dt2.0_m20.json"}) {
    const std::string file = std::string(RECRUIT_SOURCE_DIR) + f;
    EXPECT_TRUE(CheckModelPlant(file, bench).ok()) << CheckModelPlant(file, bench).error();
    const Status refused = CheckModelPlant(file, flexor);
    ASSERT_FALSE(refused.ok());
    EXPECT_NE(refused.error().find(file), std::string::npos) << refused.error();
    EXPECT_NE(refused.error().find(bench["hash"].get<std::string>()), std::string::npos);
    EXPECT_NE(refused.error().find(flexor["hash"].get<std::string>()), std::string::npos);
    EXPECT_NE(refused.error().find("series 1 vs 6"), std::string::npos) << refused.error();
  }
}

TEST(PlantRecord, FactoryRefusesAModelOfAnotherPlantAndAcceptsOneWithoutARecord) {
  const nlohmann::json flexor = Record(RECRUIT_SOURCE_DIR "/models/elbow_arm.xml", "flexor");
  auto spec = EstimatorSpec::Parse("kalman-augmented");
  ASSERT_TRUE(spec.ok());
  spec->plant = flexor;
  auto refused = MakeEstimator(*spec, 60, 0.45, 0.5);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().find("identified on another plant"), std::string::npos);
  // The same model without its plant record (e.g. fitted from a log): accepted.
  std::ifstream in(std::string(RECRUIT_SOURCE_DIR) + "/models/identified/bench_n60_dt0.5_m20.json");
  nlohmann::json j = nlohmann::json::parse(in);
  j["identification"].erase("plant");
  const std::string tmp = ::testing::TempDir() + "no_plant_model.json";
  std::ofstream(tmp) << j.dump();
  spec->model_file = tmp;
  auto accepted = MakeEstimator(*spec, 60, 0.45, 0.5);
  EXPECT_TRUE(accepted.ok()) << accepted.error();
  std::remove(tmp.c_str());
}

}  // namespace file_plant_record_test
}  // namespace recruit::identification
