// The loop designs kept between processes (control/loop_design_store.h): an entry gives back
// the design bit for bit, and a damaged, foreign or switched-off store gives nothing.
#include "control/loop_design_store.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "control/loop_design.h"

namespace recruit::control {
namespace file_loop_design_store_test {

namespace fs = std::filesystem;

// A store in a fresh folder of its own for the test's life.
class StoreFolder {
 public:
  explicit StoreFolder(const std::string& name)
      : path_(fs::temp_directory_path() /
              ("recruit_design_store_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path_);
    ::setenv("RECRUIT_DESIGN_CACHE", path_.c_str(), 1);
  }
  ~StoreFolder() {
    ::unsetenv("RECRUIT_DESIGN_CACHE");
    fs::remove_all(path_);
  }
  std::vector<fs::path> Entries() const {
    std::vector<fs::path> out;
    if (fs::exists(path_)) {
      for (const auto& e : fs::directory_iterator(path_)) out.push_back(e.path());
    }
    return out;
  }

 private:
  fs::path path_;
};

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void ExpectSameStep(const PredictedStep& a, const PredictedStep& b) {
  EXPECT_TRUE(SameBits(a.overshoot, b.overshoot));
  EXPECT_TRUE(SameBits(a.settling_time, b.settling_time));
  EXPECT_EQ(a.settled, b.settled);
  EXPECT_TRUE(SameBits(a.final_error, b.final_error));
  ASSERT_EQ(a.time.size(), b.time.size());
  ASSERT_EQ(a.angle.size(), b.angle.size());
  for (size_t i = 0; i < a.time.size(); ++i) EXPECT_TRUE(SameBits(a.time[i], b.time[i]));
  for (size_t i = 0; i < a.angle.size(); ++i) EXPECT_TRUE(SameBits(a.angle[i], b.angle[i]));
}

void ExpectSameDesign(const LoopDesign& a, const LoopDesign& b) {
  EXPECT_TRUE(SameBits(a.gains.kp, b.gains.kp));
  EXPECT_TRUE(SameBits(a.gains.ki, b.gains.ki));
  EXPECT_TRUE(SameBits(a.gains.kd, b.gains.kd));
  ExpectSameStep(a.nominal, b.nominal);
  ExpectSameStep(a.robust, b.robust);
  ExpectSameStep(a.offset, b.offset);
  EXPECT_EQ(a.meets, b.meets);
  EXPECT_EQ(a.note, b.note);
}

struct Case {
  JointDynamics joint{0.003, 0.02, 0.1};
  ActuatorResponse act = FirstOrderActuatorResponse(1.0, 0.2, 1.5);
  double dT = 1;
  LoopTarget target;
};

TEST(LoopDesignStore, ADesignIsStoredOnceAndComesBackBitForBit) {
  StoreFolder folder("roundtrip");
  Case c;
  c.target.hold = 25;  // inputs no other test designs, so this process's memo has not seen them
  auto d = DesignJointLoop(c.joint, c.act, c.dT, c.target);
  ASSERT_TRUE(d.ok()) << d.error();
  ASSERT_EQ(folder.Entries().size(), 1u) << "the search's design is stored";
  const auto key = LoopDesignKey(c.joint, c.act, c.dT, c.target);
  auto loaded = design_store::Load(key);
  ASSERT_TRUE(loaded.has_value());
  ExpectSameDesign(*loaded, *d);
  // Another input (a bit of the inertia) is another key.
  Case other = c;
  other.joint.inertia = std::nextafter(c.joint.inertia, 1.0);
  EXPECT_FALSE(design_store::Load(LoopDesignKey(other.joint, other.act, other.dT, other.target)));
}

TEST(LoopDesignStore, ADamagedEntryIsAMiss) {
  StoreFolder folder("damaged");
  Case c;
  LoopDesign d;
  d.gains = {1.5, 0.25, 0.125};
  d.nominal.time = {0, 1, 2};
  d.nominal.angle = {0, 0.5, 0.9};
  d.note = "a note";
  const auto key = LoopDesignKey(c.joint, c.act, c.dT, c.target);
  design_store::Save(key, d);
  ASSERT_EQ(folder.Entries().size(), 1u);
  ExpectSameDesign(*design_store::Load(key), d);
  const fs::path entry = folder.Entries().front();
  const auto size = fs::file_size(entry);
  fs::resize_file(entry, size - 1);  // cut short
  EXPECT_FALSE(design_store::Load(key));
  design_store::Save(key, d);
  {
    std::ofstream grow(entry, std::ios::app | std::ios::binary);
    grow << 'x';  // a byte too many
  }
  EXPECT_FALSE(design_store::Load(key));
  design_store::Save(key, d);
  {
    std::fstream edit(entry, std::ios::in | std::ios::out | std::ios::binary);
    edit.seekp(12);
    edit << '#';  // a byte of the header changed
  }
  EXPECT_FALSE(design_store::Load(key));
}

TEST(LoopDesignStore, OffStoresNothing) {
  StoreFolder folder("off");
  ::setenv("RECRUIT_DESIGN_CACHE", "off", 1);
  EXPECT_EQ(design_store::Folder(), "");
  Case c;
  const auto key = LoopDesignKey(c.joint, c.act, c.dT, c.target);
  design_store::Save(key, LoopDesign{});
  EXPECT_FALSE(design_store::Load(key));
  EXPECT_TRUE(folder.Entries().empty());
}

}  // namespace file_loop_design_store_test
}  // namespace recruit::control
