// The cache of compiled models (common/compiled_model_cache.h) against MuJoCo's own compile of
// the same file: the same model to the byte and the same steps with the plugin, a new compile
// whenever the text changes (also at the same size), nothing cached for a model that reads other
// files, damaged or foreign entries treated as misses, concurrent writers (threads and processes)
// leaving one whole entry. RECRUIT_COMPILED_CACHE points every test at its own folder.
#include "common/compiled_model_cache.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "plugin/sma_host.h"

namespace recruit {
namespace file_compiled_model_cache_test {

namespace fs = std::filesystem;

const std::string kBench = RECRUIT_SOURCE_DIR "/models/isometric_bench.xml";

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void Write(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// The model's mjb bytes (MuJoCo's own serialisation: every array and size).
std::string Bytes(const mjModel* m) {
  std::string b(static_cast<std::size_t>(mj_sizeModel(m)), '\0');
  mj_saveModel(m, nullptr, b.data(), static_cast<mjtSize>(b.size()));
  return b;
}

class CompiledModelCache : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("recruit_compiled_cache_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    cache_ = (dir_ / "cache").string();
    ::setenv("RECRUIT_COMPILED_CACHE", cache_.c_str(), 1);
  }
  void TearDown() override {
    ::unsetenv("RECRUIT_COMPILED_CACHE");
    fs::remove_all(dir_);
  }
  // Load through the cache with mj_loadXML as the compile; counts the compiles.
  mjModel* Load(const std::string& path) {
    char err[1000] = "";
    return compiled_cache::Load(
        path, "test",
        [&](char* e, int n) {
          ++compiles_;
          return mj_loadXML(path.c_str(), nullptr, e, n);
        },
        err, sizeof err);
  }
  int Entries() const {
    int n = 0;
    if (!fs::exists(cache_)) return 0;
    for (const auto& e : fs::directory_iterator(cache_)) n += e.path().extension() == ".mjb";
    return n;
  }
  int Files() const {
    int n = 0;
    if (!fs::exists(cache_)) return 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(cache_)) ++n;
    return n;
  }
  fs::path dir_;
  std::string cache_;
  int compiles_ = 0;
};

// Steps `m` with its bundles under random broadcasts; returns qpos, force and on-counts.
std::vector<double> Trace(const mjModel* m) {
  auto host = sma::SmaHost::Create(m);
  EXPECT_TRUE(host.ok());
  mjData* d = mj_makeData(m);
  (*host)->Reset(d, 7);
  std::vector<double> out;
  for (int i = 0; i < 3000; ++i) {
    if (i % 250 == 0) (void)(*host)->Broadcast(d, 0, 0.3, 0.2);
    mj_step(m, d);
    out.push_back(d->actuator_force[0]);
    out.push_back((*host)->OnCount(d, 0));
    for (int q = 0; q < m->nq; ++q) out.push_back(d->qpos[q]);
  }
  mj_deleteData(d);
  return out;
}

TEST_F(CompiledModelCache, GivesMuJoCosModelToTheByteAndTheSameSteps) {
  char err[1000];
  mjModel* direct = mj_loadXML(kBench.c_str(), nullptr, err, sizeof err);
  ASSERT_NE(direct, nullptr) << err;
  mjModel* miss = Load(kBench);
  ASSERT_NE(miss, nullptr);
  EXPECT_EQ(compiles_, 1);
  EXPECT_EQ(Entries(), 1);
  mjModel* hit = Load(kBench);
  ASSERT_NE(hit, nullptr);
  EXPECT_EQ(compiles_, 1) << "the second load is the cached one";
  EXPECT_EQ(Bytes(hit), Bytes(direct));
  // The plugin's config came through: the same bundle, stepped to the same bits.
  ASSERT_EQ(hit->nplugin, direct->nplugin);
  EXPECT_EQ(Trace(hit), Trace(direct));
  mj_deleteModel(direct);
  mj_deleteModel(miss);
  mj_deleteModel(hit);
}

TEST_F(CompiledModelCache, CompilesAgainWheneverTheTextChanges) {
  const std::string path = (dir_ / "bench.xml").string();
  const std::string text = Slurp(kBench);
  const std::string units60 = "<config key=\"units\" value=\"60\"/>";
  ASSERT_NE(text.find(units60), std::string::npos);
  auto with_units = [&](const std::string& u) {
    std::string t = text;
    t.replace(t.find(units60), units60.size(), "<config key=\"units\" value=\"" + u + "\"/>");
    return t;
  };
  auto units = [](const mjModel* m) {
    auto host = sma::SmaHost::Create(m);
    return host.ok() ? (*host)->num_units(0) : -1;
  };
  Write(path, with_units("60"));
  mjModel* a = Load(path);
  Write(path, with_units("61"));  // same size: size and time are not the key
  mjModel* b = Load(path);
  Write(path, with_units("60"));
  mjModel* c = Load(path);
  ASSERT_TRUE(a && b && c);
  EXPECT_EQ(compiles_, 2);
  EXPECT_EQ(units(a), 60);
  EXPECT_EQ(units(b), 61);
  EXPECT_EQ(units(c), 60);
  EXPECT_EQ(Entries(), 2);
  for (mjModel* m : {a, b, c}) mj_deleteModel(m);
}

TEST_F(CompiledModelCache, LeavesModelsThatReadOtherFilesToTheCompiler) {
  EXPECT_TRUE(compiled_cache::ReadsNoOtherFile("<mujoco><option profile=\"1\"/></mujoco>"));
  EXPECT_FALSE(compiled_cache::ReadsNoOtherFile("<include file=\"a.xml\"/>"));
  EXPECT_FALSE(compiled_cache::ReadsNoOtherFile("<texture fileright = \"r.png\"/>"));
  EXPECT_FALSE(compiled_cache::ReadsNoOtherFile("<mesh\nfile\n=\n'm.stl'/>"));
  // An included file's change must show: such a model is compiled every time.
  Write((dir_ / "part.xml").string(),
        "<mujoco><worldbody><geom size=\"0.1\"/></worldbody></mujoco>");
  const std::string main = (dir_ / "main.xml").string();
  Write(main, "<mujoco><include file=\"part.xml\"/></mujoco>");
  mjModel* a = Load(main);
  Write((dir_ / "part.xml").string(),
        "<mujoco><worldbody><geom size=\"0.2\"/></worldbody></mujoco>");
  mjModel* b = Load(main);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(compiles_, 2);
  EXPECT_EQ(Entries(), 0);
  EXPECT_EQ(b->geom_size[0], 0.2);
  mj_deleteModel(a);
  mj_deleteModel(b);
}

TEST_F(CompiledModelCache, TreatsDamagedOrForeignEntriesAsMisses) {
  // A plugin of another kind at another slot (one without sensors: MuJoCo's loader stops the
  // process on a plugin sensor whose slot holds it), registered before the entry is made.
  static const int other_slot = [] {
    mjpPlugin p;
    mjp_defaultPlugin(&p);
    p.name = "recruit.test_other";
    p.capabilityflags = mjPLUGIN_PASSIVE;
    return mjp_registerPlugin(&p);
  }();
  ASSERT_GE(other_slot, 0);
  mj_deleteModel(Load(kBench));
  ASSERT_EQ(Entries(), 1);
  const fs::path entry = fs::directory_iterator(cache_)->path();
  const std::string good = Slurp(entry.string());
  // The line after the header: "slot:name," of the model's plugin instance.
  const std::string header = compiled_cache::Header("test");
  ASSERT_EQ(good.compare(0, header.size(), header), 0);
  const std::size_t line_end = good.find('\n', header.size());
  const std::string slots = good.substr(header.size(), line_end - header.size());
  const std::size_t colon = slots.find(':');
  ASSERT_NE(colon, std::string::npos);
  EXPECT_EQ(slots.substr(colon), ":recruit.sma,");
  auto with_slots = [&](const std::string& line) {
    return good.substr(0, header.size()) + line + good.substr(line_end);
  };
  // Cut short; one mjb byte flipped; another process's registry in the header; the instance's
  // slot empty here, or holding the other plugin (a model names its plugins by slot, and
  // processes register plugins in different orders); another plugin's name at its slot.
  std::string flipped = good;
  flipped[flipped.size() - 100] ^= 1;
  std::string registry = good;
  registry.insert(header.size() - 1, "mujoco.pid,");
  const std::vector<std::string> bad = {good.substr(0, good.size() / 2),
                                        flipped,
                                        registry,
                                        with_slots("999:recruit.sma,"),
                                        with_slots(std::to_string(other_slot) + ":recruit.sma,"),
                                        with_slots(slots.substr(0, colon) + ":recruit.smx,")};
  // An mjb whose instance names the other plugin's slot, as a process that registered
  // recruit.sma there would write it: MuJoCo's loader would stop the process on it.
  char err[1000];
  mjModel* moved = mj_loadXML(kBench.c_str(), nullptr, err, sizeof err);
  ASSERT_NE(moved, nullptr) << err;
  moved->plugin[0] = other_slot;
  const std::string xml = Slurp(kBench), mjb = Bytes(moved);
  mj_deleteModel(moved);
  std::vector<std::string> all = bad;
  all.push_back(header + std::to_string(other_slot) + ":recruit.sma,\n" +
                std::to_string(xml.size()) + "\n" + xml + compiled_cache::MjbLine(mjb) + mjb);
  int expected = 1;
  for (const std::string& b : all) {
    Write(entry.string(), b);
    mjModel* m = Load(kBench);
    ASSERT_NE(m, nullptr);
    EXPECT_EQ(compiles_, ++expected);
    EXPECT_EQ(Slurp(entry.string()), good) << "rewritten whole";
    mj_deleteModel(m);
  }
}

TEST_F(CompiledModelCache, OffMeansNoFolderAndACompileEachTime) {
  ::setenv("RECRUIT_COMPILED_CACHE", "off", 1);
  mj_deleteModel(Load(kBench));
  mj_deleteModel(Load(kBench));
  EXPECT_EQ(compiles_, 2);
  EXPECT_FALSE(fs::exists(cache_));
}

TEST_F(CompiledModelCache, ConcurrentThreadsAndProcessesLeaveOneWholeEntry) {
  char err[1000];
  mjModel* direct = mj_loadXML(kBench.c_str(), nullptr, err, sizeof err);
  const std::string want = Bytes(direct);
  for (int round = 0; round < 3; ++round) {
    fs::remove_all(cache_);
    // Four processes, each with four threads, all loading the uncached model at once.
    std::vector<pid_t> kids;
    for (int p = 0; p < 4; ++p) {
      const pid_t pid = ::fork();
      if (pid == 0) {
        std::atomic<int> bad{0};
        std::vector<std::thread> threads;
        for (int t = 0; t < 4; ++t) {
          threads.emplace_back([&] {
            for (int i = 0; i < 5; ++i) {
              char e[1000];
              mjModel* m = compiled_cache::Load(
                  kBench, "test",
                  [&](char* e2, int n) { return mj_loadXML(kBench.c_str(), nullptr, e2, n); }, e,
                  sizeof e);
              if (m == nullptr || Bytes(m) != want) ++bad;
              if (m != nullptr) mj_deleteModel(m);
            }
          });
        }
        for (auto& t : threads) t.join();
        ::_exit(bad == 0 ? 0 : 1);
      }
      kids.push_back(pid);
    }
    for (pid_t pid : kids) {
      int status = 0;
      ASSERT_EQ(::waitpid(pid, &status, 0), pid);
      EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "a loader saw another model";
    }
    EXPECT_EQ(Entries(), 1);
    EXPECT_EQ(Files(), 1) << "no temporary file left";
    mjModel* m = Load(kBench);
    ASSERT_NE(m, nullptr);
    EXPECT_EQ(Bytes(m), want);
    mj_deleteModel(m);
  }
  EXPECT_EQ(compiles_, 0) << "every load after the writers was a hit";
  mj_deleteModel(direct);
}

}  // namespace file_compiled_model_cache_test
}  // namespace recruit
