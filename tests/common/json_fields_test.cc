#include "common/json_fields.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace recruit::json_fields {
namespace file_json_fields_test {

using nlohmann::json;

TEST(JsonFields, NumbersAreCheckedAgainstTheirRangeAndNamed) {
  const json j = json::parse(R"({"dT": 0.5, "zero": 0, "text": "x", "big": 1e308})");
  double v = -1;
  ASSERT_TRUE(Number(j, "dT", "t.json", &v, true, 0, 1000, true, "0 < dT <= 1000").ok());
  EXPECT_EQ(v, 0.5);
  // lo_open: the bound itself is refused; closed: accepted.
  Status open = Number(j, "zero", "t.json", &v, true, 0, 1, true, "0 < x <= 1");
  ASSERT_FALSE(open.ok());
  EXPECT_EQ(open.error(), "t.json.zero: 0 is out of range; allowed: 0 < x <= 1");
  EXPECT_TRUE(Number(j, "zero", "t.json", &v, true, 0, 1, false, "0 <= x <= 1").ok());
  EXPECT_FALSE(Number(j, "big", "t.json", &v, true, 0, 1e300, false, "").ok());
  Status text = Number(j, "text", "t.json", &v, true, 0, 1, false, "a fraction");
  EXPECT_EQ(text.error(), "t.json.text: must be a number (a fraction), got \"x\"");
  EXPECT_EQ(text.code(), ErrorCode::kBadInput);
  // Missing: an error when required, else *out unchanged.
  v = 7;
  EXPECT_TRUE(Number(j, "absent", "t.json", &v, false, 0, 1, false, "").ok());
  EXPECT_EQ(v, 7);
  EXPECT_EQ(Number(j, "absent", "t.json", &v, true, 0, 1, false, "0..1").error(),
            "t.json: missing field 'absent' (0..1)");
}

TEST(JsonFields, IntegersRefuseFractionsAndValuesOutsideTheRange) {
  const json j = json::parse(R"({"a": 3, "b": 2.5, "c": 0, "d": 18446744073709551615, "e": -1})");
  std::int64_t n = 0;
  EXPECT_TRUE(Integer(j, "a", "w", &n, true, 1, 10, "1..10").ok());
  EXPECT_EQ(n, 3);
  EXPECT_EQ(Integer(j, "b", "w", &n, true, 1, 10, "1..10").error(), "w.b: 2.5; allowed: 1..10");
  EXPECT_FALSE(Integer(j, "c", "w", &n, true, 1, 10, "1..10").ok());
  EXPECT_FALSE(Integer(j, "d", "w", &n, true, 1, 10, "1..10").ok());  // not wrapped to -1
  std::uint64_t u = 0;
  EXPECT_TRUE(Unsigned(j, "d", "w", &u, true).ok());
  EXPECT_EQ(u, std::numeric_limits<std::uint64_t>::max());
  EXPECT_FALSE(Unsigned(j, "e", "w", &u, true).ok());
}

// Arrays of whole numbers and of booleans: the length, then each entry, named by its index.
TEST(JsonFields, IntegerAndBooleanArraysNameTheEntry) {
  const json j = json::parse(
      R"({"t": [1, -1, 2], "f": [1, 2.0], "big": [18446744073709551615], "on": [true, false],
          "bits": [true, 0], "short": [true]})");
  std::vector<std::int64_t> t;
  EXPECT_TRUE(Integers(j, "t", "w", &t, true, 3, -1, 5, "indices").ok());
  EXPECT_EQ(t, (std::vector<std::int64_t>{1, -1, 2}));
  EXPECT_EQ(Integers(j, "t", "w", &t, true, 2, -1, 5, "2 indices").error(),
            "w.t: [1,-1,2]; allowed: 2 indices");
  EXPECT_EQ(Integers(j, "t", "w", &t, true, 3, 0, 5, "indices >= 0").error(),
            "w.t[1]: -1; allowed: indices >= 0");
  EXPECT_EQ(Integers(j, "f", "w", &t, true, -1, 0, 5, "i").error(), "w.f[1]: 2.0; allowed: i");
  EXPECT_FALSE(Integers(j, "big", "w", &t, true, -1, -1, 5, "i").ok());  // not wrapped to -1
  EXPECT_EQ(Integers(j, "absent", "w", &t, true, 3, 0, 5, "indices").error(),
            "w: missing field 'absent' (indices)");
  EXPECT_EQ(t, (std::vector<std::int64_t>{1, -1, 2}));  // unchanged by the failures
  std::vector<bool> b;
  EXPECT_TRUE(Booleans(j, "on", "w", &b, true, 2, "flags").ok());
  EXPECT_EQ(b, (std::vector<bool>{true, false}));
  EXPECT_EQ(Booleans(j, "bits", "w", &b, true, 2, "flags").error(),
            "w.bits[1]: 0; allowed: true or false");
  EXPECT_EQ(Booleans(j, "short", "w", &b, true, 2, "2 flags").error(),
            "w.short: [true]; allowed: 2 flags");
  EXPECT_TRUE(Booleans(j, "absent", "w", &b, false, 2, "flags").ok());
}

TEST(JsonFields, UnknownKeysAreNamedWithTheAllowedOnes) {
  const json j = json::parse(R"({"kp": 1, "colour": 2})");
  Status s = CheckKeys(j, {"kp", "ki"}, "t.json.outer_loop");
  EXPECT_EQ(s.error(), "t.json.outer_loop: unknown field 'colour'; allowed: ki, kp");
  EXPECT_TRUE(CheckKeys(j, {"kp", "colour"}, "w").ok());
}

TEST(JsonFields, StringsBooleansAndVectors) {
  const json j = json::parse(R"({"s": "ok", "e": "", "b": true, "v": [1, 2, 3], "w": [1, 2]})");
  std::string s;
  EXPECT_TRUE(String(j, "s", "w", &s, true).ok());
  EXPECT_EQ(s, "ok");
  EXPECT_FALSE(String(j, "e", "w", &s, true).ok());
  bool b = false;
  EXPECT_TRUE(Boolean(j, "b", "w", &b).ok());
  EXPECT_TRUE(b);
  EXPECT_FALSE(Boolean(j, "s", "w", &b).ok());
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  EXPECT_TRUE(Vec3(j, "v", "w", &v).ok());
  EXPECT_EQ(v, Eigen::Vector3d(1, 2, 3));
  EXPECT_FALSE(Vec3(j, "w", "w", &v).ok());
}

TEST(JsonFields, ChoicesNamesAndObjects) {
  const json j =
      json::parse(R"({"type": "magic", "ok": "b", "names": ["a", ""], "o": {}, "n": 1})");
  std::string s;
  EXPECT_TRUE(OneOf(j, "ok", "w", &s, true, {"a", "b"}).ok());
  EXPECT_EQ(s, "b");
  EXPECT_EQ(OneOf(j, "type", "w", &s, true, {"a", "b"}).error(),
            "w.type: \"magic\"; allowed: \"a\", \"b\"");
  EXPECT_EQ(OneOf(j, "absent", "w", &s, true, {"a", "b"}).error(),
            "w: missing field 'absent' (one of \"a\", \"b\")");
  std::vector<std::string> names = {"kept"};
  EXPECT_EQ(Strings(j, "names", "w", &names, true).error(),
            "w.names[1]: must be a non-empty string, got \"\"");
  EXPECT_EQ(names, std::vector<std::string>{"kept"});  // unchanged on error
  EXPECT_EQ(Strings(j, "n", "w", &names, true).error(),
            "w.n: must be a non-empty array of names, got 1");
  EXPECT_TRUE(Object(j, "o", "w", true, "{x}").ok());
  EXPECT_TRUE(Object(j, "absent", "w", false, "{x}").ok());
  EXPECT_EQ(Object(j, "n", "w", false, "{x}").error(), "w.n: must be an object ({x}), got 1");
}

TEST(JsonFields, MatricesAndVectorsNameTheEntry) {
  const json j = json::parse(R"({"M": [[1, 2], [3, 4]], "ragged": [[1, 2], [3]],
                                 "text": [[1, "x"]], "v": [1, 2, 3], "flat": 5})");
  Eigen::MatrixXd M;
  ASSERT_TRUE(Matrix(j, "M", "w", &M, true, -1, 2).ok());
  EXPECT_EQ(M, (Eigen::MatrixXd(2, 2) << 1, 2, 3, 4).finished());  // row-major
  EXPECT_EQ(Matrix(j, "M", "w", &M, true, 3, 2).error(),
            "w.M: must have 3 rows (a 3 x 2 matrix), got 2");
  EXPECT_EQ(Matrix(j, "ragged", "w", &M, true, -1, -1).error(),
            "w.ragged[1]: must be an array of 2 numbers (row 1 of a r x c matrix), got [3]");
  EXPECT_EQ(Matrix(j, "text", "w", &M, true, 1, 2).error(),
            "w.text[0][1]: must be a finite number, got \"x\"");
  EXPECT_EQ(Matrix(j, "flat", "w", &M, true, 1, 1).error(),
            "w.flat: must be an array of rows (a 1 x 1 matrix, row-major), got 5");
  EXPECT_EQ(Matrix(j, "absent", "w", &M, true, 2, 2).error(),
            "w: missing field 'absent' (a 2 x 2 matrix, an array of rows)");
  Eigen::VectorXd v;
  ASSERT_TRUE(Vector(j, "v", "w", &v, true, 3).ok());
  EXPECT_EQ(v, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(Vector(j, "v", "w", &v, true, 2).error(), "w.v: must have 2 entries, got 3");
  // A NaN can only come from a document made in code (JSON has none): refused too.
  const json nan = {{"v", {1.0, std::nan("")}}};
  EXPECT_EQ(Vector(nan, "v", "w", &v, true, -1).error(),
            "w.v[1]: must be a finite number, got null");
}

TEST(JsonFields, LongValuesAreShortenedInMessages) {
  const json j = {{"x", std::string(5000, 'a')}};
  double v = 0;
  Status s = Number(j, "x", "w", &v, true, 0, 1, false, "0..1");
  ASSERT_FALSE(s.ok());
  EXPECT_LT(s.error().size(), 120u) << s.error();
}

}  // namespace file_json_fields_test
}  // namespace recruit::json_fields
