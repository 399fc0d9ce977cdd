#include "identification/model_cache.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include "common/atomic_file.h"

namespace recruit::identification {
namespace {

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

}  // namespace
}  // namespace recruit::identification
