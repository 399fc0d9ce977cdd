#include "common/atomic_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

namespace recruit {
namespace {

namespace fs = std::filesystem;

fs::path TempDir() {
  fs::path p = fs::temp_directory_path() / ("recruit_atomic_" + std::to_string(::getpid()));
  fs::create_directories(p);
  return p;
}

TEST(AtomicFile, CommitWritesContentsAndLeavesNoTemporary) {
  const fs::path dir = TempDir();
  const std::string path = (dir / "out.csv").string();
  ASSERT_TRUE(WriteFileAtomically(path, "a,b\n1,2\n").ok());
  auto read = ReadFile(path);
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_EQ(*read, "a,b\n1,2\n");
  int files = 0;
  for (auto& e : fs::directory_iterator(dir)) files += e.is_regular_file();
  EXPECT_EQ(files, 1);
  fs::remove_all(dir);
}

TEST(AtomicFile, WithoutCommitNothingIsLeftBehind) {
  const fs::path dir = TempDir();
  const std::string path = (dir / "half.csv").string();
  {
    AtomicFile f(path);
    ASSERT_TRUE(f.ok());
    f.stream() << "partial";
  }
  EXPECT_FALSE(fs::exists(path));
  EXPECT_TRUE(fs::is_empty(dir));
  fs::remove_all(dir);
}

TEST(AtomicFile, UnwritableDirectoryGivesErrorNamingPath) {
  AtomicFile f("/nonexistent_dir_recruit/x.csv");
  EXPECT_FALSE(f.ok());
  EXPECT_NE(f.error().find("/nonexistent_dir_recruit/x.csv"), std::string::npos);
  EXPECT_FALSE(f.Commit().ok());
}

TEST(ReadFile, MissingFileErrorNamesIt) {
  auto r = ReadFile("/no/such/file.json");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("/no/such/file.json"), std::string::npos);
}

}  // namespace
}  // namespace recruit
