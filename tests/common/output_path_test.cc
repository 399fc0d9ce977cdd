#include "common/output_path.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <vector>

#include "common/atomic_file.h"
#include "common/content_hash.h"
#include "common/exit_codes.h"
#include "common/file_lock.h"
#include "common/json_file.h"
#include "common/short_text.h"

namespace recruit {
namespace file_output_path_test {
namespace fs = std::filesystem;

TEST(OutputPath, NamesThatWouldLeaveTheOutputFolderAreRefused) {
  for (const std::string& bad :
       std::vector<std::string>{"../escaped", "/etc/passwd", "a/b", "..", ".", ".hidden", "",
                                "tab\there", "new\nline", "sp ace", std::string(101, 'a')}) {
    Status s = CheckFileNameComponent(bad, "task.json: name");
    EXPECT_FALSE(s.ok()) << "accepted '" << bad << "'";
    if (!s.ok()) {
      EXPECT_NE(s.error().find("task.json: name"), std::string::npos);
      EXPECT_EQ(s.error().find('\n'), std::string::npos) << "control character echoed";
    }
  }
  for (const std::string& good :
       std::vector<std::string>{"isometric_steps", "arm-lift.v2", "a+b", std::string(100, 'a')}) {
    EXPECT_TRUE(CheckFileNameComponent(good, "name").ok()) << good;
  }
}

TEST(OutputPath, AnOutputThatIsAnInputIsRefusedThroughAnyPath) {
  const fs::path dir = fs::temp_directory_path() / ("recruit_outpath_" + std::to_string(getpid()));
  fs::create_directories(dir / "sub");
  const fs::path in = dir / "in.json";
  std::ofstream(in) << "{}";
  fs::create_symlink(in, dir / "link.json");
  EXPECT_FALSE(CheckNotAnInput(in.string(), "--out", {{"--task", in.string()}}).ok());
  EXPECT_FALSE(
      CheckNotAnInput((dir / "sub" / ".." / "in.json").string(), "--out", {{"--task", in.string()}})
          .ok());
  Status via_link =
      CheckNotAnInput((dir / "link.json").string(), "--out", {{"--task", in.string()}});
  ASSERT_FALSE(via_link.ok());
  EXPECT_NE(via_link.error().find("refusing to overwrite an input"), std::string::npos);
  EXPECT_TRUE(CheckNotAnInput((dir / "out.json").string(), "--out",
                              {{"--task", in.string()}, {"--model", ""}})
                  .ok());
  fs::remove_all(dir);
}

TEST(ShortText, LongValuesAndControlCharactersAreShortened) {
  EXPECT_EQ(ShortText("abc"), "abc");
  EXPECT_EQ(ShortText(std::string(50, 'x'), 40), std::string(40, 'x') + "... (50 characters)");
  EXPECT_EQ(ShortText("a\x1b[2Jb"), "a?[2Jb");
  EXPECT_EQ(ShortenLongTokens("Could not convert: --dT = " + std::string(45, '9'), 40),
            "Could not convert: --dT = " + std::string(40, '9') + "... (45 characters)");
}

TEST(ExitCodes, TheClassTravelsWithTheErrorNotItsWording) {
  // A failed write is I/O (4) and a malformed JSON file bad input (3), read from their codes.
  Status w = WriteFileAtomically("/proc/nonexistent/x.json", "{}");
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(exit_code::Of(w.failure()), exit_code::kIo);
  const std::string bad =
      (fs::temp_directory_path() / ("recruit_bad_" + std::to_string(getpid()) + ".json")).string();
  ASSERT_TRUE(WriteFileAtomically(bad, "{\"a\": ").ok());
  auto j = LoadJsonFile(bad);
  fs::remove(bad);
  ASSERT_FALSE(j.ok());
  EXPECT_EQ(exit_code::Of(j.failure()), exit_code::kBadInput);
  // Wording decides nothing: "cannot open" in a bad-input message stays 3, any I/O message is 4.
  EXPECT_EQ(exit_code::Of(Error{"cannot open: a field's value"}), exit_code::kBadInput);
  EXPECT_EQ(exit_code::Of(IoError("the disk said no")), exit_code::kIo);
  // Wrapping keeps the class.
  Result<int> inner = IoError("x.csv: short read");
  const Error outer = inner.failure().In("task.json: ");
  EXPECT_EQ(outer.message, "task.json: x.csv: short read");
  EXPECT_EQ(outer.code, ErrorCode::kIo);
  EXPECT_EQ(exit_code::Of(ErrorCode::kUsage), exit_code::kUsage);
  EXPECT_EQ(exit_code::Of(ErrorCode::kInternal), exit_code::kInternal);
  // Failed filesystem calls: a path that names no file is bad input; a file that is there but
  // cannot be opened, read or written (access, not a regular file, space, size, read-only, a
  // device error) is I/O.
  for (int err : {ENOENT, ENOTDIR, ENAMETOOLONG, ELOOP}) {
    EXPECT_EQ(CodeOf(std::error_code(err, std::generic_category())), ErrorCode::kBadInput) << err;
  }
  for (int err : {EACCES, ENXIO, EISDIR, ENOSPC, EFBIG, EROFS, EIO}) {
    EXPECT_EQ(CodeOf(std::error_code(err, std::generic_category())), ErrorCode::kIo) << err;
  }
}

TEST(FileLock, ASecondLockOnTheSameFileFailsUntilTheFirstIsReleased) {
  const std::string path =
      (fs::temp_directory_path() / ("recruit_lock_" + std::to_string(getpid()))).string();
  {
    auto first = FileLock::TryLock(path);
    ASSERT_TRUE(first.ok()) << first.error();
    auto second = FileLock::TryLock(path);  // another open file description: conflicts
    ASSERT_FALSE(second.ok());
    EXPECT_NE(second.error().find("pid " + std::to_string(getpid())), std::string::npos)
        << second.error();
  }
  EXPECT_TRUE(FileLock::TryLock(path).ok());
  fs::remove(path);
}

TEST(ContentHash, FieldsAreDelimitedAndAnyByteChangesTheHash) {
  EXPECT_NE(ContentHash().Add("ab").Add("c").Hex(), ContentHash().Add("a").Add("bc").Hex());
  EXPECT_NE(ContentHash().Add("duration 60").Hex(), ContentHash().Add("duration 61").Hex());
  EXPECT_EQ(ContentHash().Add("x").Hex(), ContentHash().Add("x").Hex());
  EXPECT_STRNE(CodeVersion(), "");
}

}  // namespace file_output_path_test
}  // namespace recruit
