#include "identification/model_cache.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include "common/atomic_file.h"
#include "identification/plant_record.h"

namespace recruit::identification {
namespace file_model_cache_test {

namespace fs = std::filesystem;

// A cached model is used only when it records this build's identification version; without
// identification allowed, an outdated one is reported missing (with it, it would be made again).
TEST(ModelCache, ACachedModelOfAnotherIdentificationVersionIsNotUsed) {
  const fs::path cache =
      fs::temp_directory_path() / ("recruit_model_cache_test_" + std::to_string(getpid()));
  fs::create_directories(cache);
  ASSERT_EQ(setenv("RECRUIT_MODEL_CACHE", cache.c_str(), 1), 0);
  ASSERT_EQ(unsetenv("RECRUIT_MODEL_PATH"), 0);
  ModelRequest r;
  r.model_path = "unused.xml";
  r.actuator = "flexor";
  r.plant = {{"actuator", "flexor"}, {"hash", "feedfacefeedface"}};
  r.dT = 0.5;
  r.num_states = 4;
  const fs::path file = cache / ModelFileName(r.plant, r.dT, r.num_states);
  EXPECT_EQ(file.filename(), "flexor_feedfacefeedface_dt0.5_m4.json");
  EXPECT_FALSE(FindOrIdentifyModel(r, false, nullptr).ok());  // none yet

  for (const auto& [version, used] :
       {std::pair{kIdentificationVersion - 1, false}, std::pair{kIdentificationVersion, true}}) {
    const nlohmann::json model = {{"identification", {{"version", version}}}};
    ASSERT_TRUE(WriteFileAtomically(file.string(), model.dump()).ok());
    EXPECT_EQ(MadeByThisIdentification(file.string()), used) << version;
    auto found = FindOrIdentifyModel(r, false, nullptr);
    EXPECT_EQ(found.ok(), used) << version;
    if (used && found.ok()) {
      EXPECT_EQ(*found, file.string());
    }
  }
  ASSERT_TRUE(WriteFileAtomically(file.string(), "{\"H\": []}").ok());  // no version: outdated
  EXPECT_FALSE(FindOrIdentifyModel(r, false, nullptr).ok());
  unsetenv("RECRUIT_MODEL_CACHE");
  fs::remove_all(cache);
}

// Identification runs on the limb, so the cache keys its models by the limb too: a bundle of the
// same units on another limb is identified again, not given the first limb's model; a model
// named without a limb, put in a folder on the search path on purpose, serves every limb.
TEST(ModelCache, ACachedModelIsTheLimbsItWasIdentifiedOn) {
  const fs::path dir =
      fs::temp_directory_path() / ("recruit_model_cache_limb_" + std::to_string(getpid()));
  const fs::path cache = dir / "cache", shelf = dir / "shelf";
  fs::create_directories(cache);
  fs::create_directories(shelf);
  ASSERT_EQ(setenv("RECRUIT_MODEL_CACHE", cache.c_str(), 1), 0);
  ASSERT_EQ(unsetenv("RECRUIT_MODEL_PATH"), 0);
  // Two limbs that differ in one byte.
  const fs::path limb_a = dir / "a.xml", limb_b = dir / "b.xml";
  ASSERT_TRUE(WriteFileAtomically(limb_a.string(), "<mujoco model=\"a\"/>").ok());
  ASSERT_TRUE(WriteFileAtomically(limb_b.string(), "<mujoco model=\"b\"/>").ok());
  const std::string hash_a = LimbHash(limb_a.string()), hash_b = LimbHash(limb_b.string());
  ASSERT_EQ(hash_a.size(), 16u);
  ASSERT_NE(hash_a, hash_b);
  EXPECT_EQ(LimbHash((dir / "missing.xml").string()), "");
  auto request = [](const fs::path& limb, const std::string& hash) {
    ModelRequest r;
    r.model_path = limb.string();
    r.actuator = "flexor";
    r.plant = {{"actuator", "flexor"}, {"hash", "feedfacefeedface"}, {"limb", hash}};
    r.dT = 1;
    r.num_states = 4;
    return r;
  };
  const ModelRequest a = request(limb_a, hash_a), b = request(limb_b, hash_b);
  EXPECT_EQ(ModelFileName(a.plant, 1, 4), "flexor_feedfacefeedface_" + hash_a + "_dt1_m4.json");
  EXPECT_EQ(ModelFileName(a.plant, 1, 4, false), "flexor_feedfacefeedface_dt1_m4.json");
  const nlohmann::json model = {{"identification", {{"version", kIdentificationVersion}}}};
  const fs::path made_a = cache / ModelFileName(a.plant, 1, 4);
  ASSERT_TRUE(WriteFileAtomically(made_a.string(), model.dump()).ok());
  auto found_a = FindOrIdentifyModel(a, false, nullptr);
  ASSERT_TRUE(found_a.ok()) << found_a.error();
  EXPECT_EQ(*found_a, made_a.string());
  EXPECT_FALSE(FindOrIdentifyModel(b, false, nullptr).ok());  // limb a's is not limb b's
  // Nor is a model named without the limb in the cache (one of an older build) anyone's.
  ASSERT_TRUE(
      WriteFileAtomically((cache / ModelFileName(b.plant, 1, 4, false)).string(), model.dump())
          .ok());
  EXPECT_FALSE(FindOrIdentifyModel(b, false, nullptr).ok());
  // On the search path, one without the limb serves both; one of the limb comes first.
  ASSERT_EQ(setenv("RECRUIT_MODEL_PATH", shelf.c_str(), 1), 0);
  const fs::path any = shelf / ModelFileName(b.plant, 1, 4, false);
  ASSERT_TRUE(WriteFileAtomically(any.string(), model.dump()).ok());
  auto found_b = FindOrIdentifyModel(b, false, nullptr);
  ASSERT_TRUE(found_b.ok()) << found_b.error();
  EXPECT_EQ(*found_b, any.string());
  const fs::path own = shelf / ModelFileName(a.plant, 1, 4);
  ASSERT_TRUE(WriteFileAtomically(own.string(), model.dump()).ok());
  found_a = FindOrIdentifyModel(a, false, nullptr);
  ASSERT_TRUE(found_a.ok());
  EXPECT_EQ(*found_a, own.string());
  unsetenv("RECRUIT_MODEL_PATH");
  unsetenv("RECRUIT_MODEL_CACHE");
  fs::remove_all(dir);
}

}  // namespace file_model_cache_test
}  // namespace recruit::identification
