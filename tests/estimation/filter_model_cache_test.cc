// ParseFilterModelFile: the same model and JSON as a fresh parse, a new parse for every change of
// the bytes (also at the same size), errors as a fresh parse gives them and never kept, and
// threads that load more files than the cache holds each get their own file's model.
#include "estimation/filter_model_cache.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "common/atomic_file.h"
#include "common/json_file.h"

namespace recruit {
namespace file_filter_model_cache_test {

namespace fs = std::filesystem;
using estimation::FilterModel;
using estimation::ParseFilterModelFile;

std::string Shipped() {
  std::ifstream in(std::string(RECRUIT_SOURCE_DIR) + "/models/identified/bench_n60_dt2.0_m20.json");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void Write(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
}

// The file parsed without the cache.
Result<FilterModel> Fresh(const std::string& path) {
  auto text = ReadFile(path);
  if (!text.ok()) return text.failure();
  auto j = ParseJsonText(*text, path);
  if (!j.ok()) return j.failure();
  return FilterModel::FromJsonValue(*j, path);
}

class FilterModelCache : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("recruit_fmc_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string File(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

TEST_F(FilterModelCache, GivesTheModelAndJsonOfAFreshParseAndKeepsThem) {
  const std::string path = File("m.json"), text = Shipped();
  ASSERT_NE(text.find("\"N\": 60"), std::string::npos);
  Write(path, text);
  auto a = ParseFilterModelFile(path);
  ASSERT_TRUE(a.ok()) << a.error();
  auto fresh = Fresh(path);
  ASSERT_TRUE(fresh.ok()) << fresh.error();
  EXPECT_EQ((*a)->model.ToJson(), fresh->ToJson());
  EXPECT_EQ((*a)->model.holdout_r2, fresh->holdout_r2);
  EXPECT_EQ((*a)->json, nlohmann::json::parse(text));
  auto b = ParseFilterModelFile(path);
  ASSERT_TRUE(b.ok());
  EXPECT_EQ(a->get(), b->get());  // kept: the same parse
  auto via = FilterModel::FromJson(path);
  ASSERT_TRUE(via.ok());
  EXPECT_EQ(via->ToJson(), fresh->ToJson());
}

TEST_F(FilterModelCache, ParsesAgainWhenTheBytesChangeAtTheSameSize) {
  const std::string path = File("m.json");
  std::string text = Shipped();
  Write(path, text);
  auto a = ParseFilterModelFile(path);
  ASSERT_TRUE(a.ok()) << a.error();
  const double h0 = (*a)->model.H(0, 0);
  const std::string entry = "2.1788676195233503e-07";  // H(0, 0)
  ASSERT_NE(text.find(entry), std::string::npos);
  text.replace(text.find(entry), entry.size(), "3.1788676195233503e-07");
  Write(path, text);
  auto b = ParseFilterModelFile(path);
  ASSERT_TRUE(b.ok()) << b.error();
  EXPECT_NE((*b)->model.H(0, 0), h0);
  EXPECT_EQ((*b)->model.H(0, 0), 3.1788676195233503e-07);
  EXPECT_EQ((*b)->model.ToJson(), Fresh(path)->ToJson());
  // The same bytes under another path: messages name the path, so it is its own entry.
  const std::string other = File("other.json");
  Write(other, text);
  auto c = ParseFilterModelFile(other);
  ASSERT_TRUE(c.ok());
  EXPECT_NE(b->get(), c->get());
}

TEST_F(FilterModelCache, ErrorsAreAFreshParsesAndAreNotKept) {
  const std::string path = File("m.json");
  std::string text = Shipped();
  std::string bad = text;
  bad.replace(bad.find("\"N\": 60"), 7, "\"N\": -6");
  Write(path, bad);
  auto a = ParseFilterModelFile(path);
  ASSERT_FALSE(a.ok());
  EXPECT_EQ(a.error(), Fresh(path).error());
  EXPECT_NE(a.error().find(path), std::string::npos) << a.error();
  Write(path, "{ not json");
  auto b = ParseFilterModelFile(path);
  ASSERT_FALSE(b.ok());
  EXPECT_EQ(b.error(), Fresh(path).error());
  Write(path, text);
  auto c = ParseFilterModelFile(path);
  ASSERT_TRUE(c.ok()) << c.error();
  EXPECT_EQ((*c)->model.N, 60);
  fs::remove(path);
  auto d = ParseFilterModelFile(path);  // a file gone is an error, not the kept parse
  ASSERT_FALSE(d.ok());
  EXPECT_EQ(d.error(), Fresh(path).error());
}

TEST_F(FilterModelCache, ThreadsLoadingMoreFilesThanItHoldsGetTheirOwn) {
  const std::string text = Shipped();
  const int files = estimation::kFilterModelCacheEntries + 4;
  // Each file its own H(0, 0) (the last two digits of its mantissa), at the same size.
  const std::string entry = "2.1788676195233503e-07";
  std::vector<std::string> paths;
  std::vector<double> h0;
  for (int i = 0; i < files; ++i) {
    std::string t = text;
    char digits[3];
    std::snprintf(digits, sizeof digits, "%02d", i);
    t.replace(t.find(entry), entry.size(), entry.substr(0, 16) + digits + "e-07");
    paths.push_back(File("m" + std::to_string(i) + ".json"));
    Write(paths.back(), t);
    h0.push_back(Fresh(paths.back())->H(0, 0));
  }
  std::vector<int> wrong(4, 0);
  std::vector<std::thread> threads;
  for (int w = 0; w < 4; ++w) {
    threads.emplace_back([&, w] {
      for (int k = 0; k < 60; ++k) {
        const int i = (k * 7 + w * 3) % files;
        auto r = ParseFilterModelFile(paths[i]);
        if (!r.ok() || (*r)->model.H(0, 0) != h0[i]) ++wrong[w];
      }
    });
  }
  for (auto& t : threads) t.join();
  for (int w = 0; w < 4; ++w) EXPECT_EQ(wrong[w], 0) << "thread " << w;
}

}  // namespace file_filter_model_cache_test
}  // namespace recruit
