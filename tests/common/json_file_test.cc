#include "common/json_file.h"

#include <gtest/gtest.h>

#include <string>

namespace recruit {
namespace file_json_file_test {

TEST(JsonFile, ParsesPlainJsonAndSkipsAByteOrderMark) {
  auto j = ParseJsonText("\xEF\xBB\xBF{\"a\": [1, 2.5]}", "t.json");
  ASSERT_TRUE(j.ok()) << j.error();
  EXPECT_EQ((*j)["a"][1].get<double>(), 2.5);
}

TEST(JsonFile, NumberTooLargeForADoubleIsAClearErrorNotAnAbort) {
  auto j = ParseJsonText("{\"duration\": 1e999}", "task.json");
  ASSERT_FALSE(j.ok());
  EXPECT_NE(j.error().find("task.json"), std::string::npos) << j.error();
  EXPECT_NE(j.error().find("too large for a double"), std::string::npos) << j.error();
}

TEST(JsonFile, DeepNestingIsRefusedBeforeParsing) {
  const std::string deep = std::string(70000, '[') + std::string(70000, ']');
  auto j = ParseJsonText(deep, "deep.json");
  ASSERT_FALSE(j.ok());
  EXPECT_NE(j.error().find("nested more than 128"), std::string::npos) << j.error();
  // The limit is exact: 128 levels pass, 129 do not.
  EXPECT_TRUE(ParseJsonText(std::string(128, '[') + std::string(128, ']'), "x").ok());
  EXPECT_FALSE(ParseJsonText(std::string(129, '[') + std::string(129, ']'), "x").ok());
}

TEST(JsonFile, BracketsInsideStringsDoNotCountAsNesting) {
  EXPECT_EQ(JsonNestingDepth("{\"a\": \"[[[[\\\"[[\", \"b\": [{}]}", 100), 3);
  auto j =
      ParseJsonText("{\"name\": \"" + std::string(500, '[') + "\"}", "x", JsonLimits{1 << 20, 4});
  EXPECT_TRUE(j.ok()) << j.error();
}

TEST(JsonFile, SizeLimitAndShortenedMessages) {
  JsonLimits small;
  small.max_bytes = 10;
  auto big = ParseJsonText("[1, 2, 3, 4, 5, 6]", "big.json", small);
  ASSERT_FALSE(big.ok());
  EXPECT_NE(big.error().find("at most 10"), std::string::npos) << big.error();
  // A 2 MB bad token must not come back whole in the message.
  auto bad = ParseJsonText("{\"a\": " + std::string(2 << 20, 'x') + "}", "bad.json");
  ASSERT_FALSE(bad.ok());
  EXPECT_LT(bad.error().size(), 600u);
  EXPECT_NE(bad.error().find("bad.json: not valid JSON"), std::string::npos) << bad.error();
}

// ReadFile's classes (CodeOf): a path that names no file is bad input, not I/O.
TEST(JsonFile, AMissingFileIsBadInput) {
  auto j = LoadJsonFile("/nonexistent/dir/x.json");
  ASSERT_FALSE(j.ok());
  EXPECT_EQ(j.error().rfind("cannot read '/nonexistent/dir/x.json'", 0), 0u) << j.error();
  EXPECT_EQ(j.code(), ErrorCode::kBadInput);
}

}  // namespace file_json_file_test
}  // namespace recruit
