// Filter model files: validation messages and the JSON round trip.
#include "estimation/filter_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "common/exit_codes.h"
#include "estimation/count_filter.h"
#include "estimation/filter_log.h"
#include "estimation/population_chain.h"

namespace recruit {
namespace file_filter_model_test {

TEST(EstimationBroadcast, TwoStateMatrixIsTheClosedForm) {
  const auto b = estimation::BroadcastTransitionModel::TwoState(0.5);
  ASSERT_TRUE(b.Validate().ok()) << b.Validate().error();
  const Eigen::MatrixXd A = b.Matrix(0.3, 0.1);
  Eigen::Matrix2d expected;
  expected << 0.7, 0.1, 0.3, 0.9;
  EXPECT_LT((A - expected).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(EstimationBroadcast, AugmentedModelColumns) {
  // off0 (cold) --p_on--> on0 ; on0 --interior--> on1 ; on states --p_off--> off1 (cooling).
  estimation::BroadcastTransitionModel b;
  b.state_names = {"off0", "off1", "on0", "on1"};
  b.is_on = {false, false, true, true};
  b.interior.setZero(4, 4);
  b.interior.col(0) << 1, 0, 0, 0;
  b.interior.col(1) << 0.4, 0.6, 0, 0;
  b.interior.col(2) << 0, 0, 0.5, 0.5;
  b.interior.col(3) << 0, 0, 0, 1;
  b.on_target = {2, 2, -1, -1};
  b.off_target = {-1, -1, 1, 1};
  b.dt = 0.5;
  ASSERT_TRUE(b.Validate().ok()) << b.Validate().error();
  const Eigen::MatrixXd A = b.Matrix(0.2, 0.3);
  EXPECT_TRUE(estimation::ValidateColumnStochastic(A).ok());
  // Column 1 (off1): 0.8 * (0.4, 0.6, 0, 0) + 0.2 e_2.
  EXPECT_NEAR(A(0, 1), 0.32, 1e-15);
  EXPECT_NEAR(A(1, 1), 0.48, 1e-15);
  EXPECT_NEAR(A(2, 1), 0.2, 1e-15);
  // Column 2 (on0): 0.7 * (0, 0, 0.5, 0.5) + 0.3 e_1.
  EXPECT_NEAR(A(1, 2), 0.3, 1e-15);
  EXPECT_NEAR(A(2, 2), 0.35, 1e-15);
  EXPECT_NEAR(A(3, 2), 0.35, 1e-15);
  b.off_target[3] = 7;
  Status s = b.Validate("m.json: transition");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().find("m.json: transition.off_target[3] = 7"), std::string::npos) << s.error();
}

TEST(EstimationFilterModel, SaveAndLoadRoundTrip) {
  estimation::FilterModel f = estimation::FilterModel::TwoState(60, 0.5, 0.45, 0.3);
  f.x0 = Eigen::Vector2d(50, 10);
  f.P0 = Eigen::Matrix2d{{4, -4}, {-4, 4}};
  const std::string path = testing::TempDir() + "/estimation_model_roundtrip.json";
  ASSERT_TRUE(f.Save(path).ok());
  auto g = estimation::FilterModel::FromJson(path);
  ASSERT_TRUE(g.ok()) << g.error();
  EXPECT_EQ(g->state_names, f.state_names);
  EXPECT_EQ(g->N, 60);
  EXPECT_EQ(g->H, f.H);
  EXPECT_EQ(g->R, f.R);
  EXPECT_EQ(g->x0, f.x0);
  EXPECT_EQ(g->P0, f.P0);
  EXPECT_EQ(g->broadcast.Matrix(0.2, 0.4), f.broadcast.Matrix(0.2, 0.4));
  EXPECT_FALSE(g->has_transit_noise());
  // A model without transit noise writes no R_transit (old readers see the file they knew).
  EXPECT_FALSE(g->ToJson().contains("R_transit"));
  // Each transit term alone: written, read back, the other not written.
  auto reload = [&path](const estimation::FilterModel& m) {
    EXPECT_TRUE(m.Save(path).ok());
    auto r = estimation::FilterModel::FromJson(path);
    EXPECT_TRUE(r.ok()) << r.error();
    return r.ok() ? *r : m;
  };
  f.R_transit(0, 0) = 0.125;
  const estimation::FilterModel t = reload(f);
  EXPECT_EQ(t.R_transit, f.R_transit);
  EXPECT_TRUE(t.has_transit_noise());
  EXPECT_FALSE(t.ToJson().contains("R_transit2"));
  f.R_transit(0, 0) = 0;
  f.R_transit2 = Eigen::MatrixXd::Constant(1, 1, 0.0625);
  const estimation::FilterModel u = reload(f);
  EXPECT_EQ(u.R_transit2, f.R_transit2);
  EXPECT_TRUE(u.has_transit_noise());
  EXPECT_FALSE(u.ToJson().contains("R_transit"));
  std::remove(path.c_str());
}

// A state's transit weight is the force between it and the state its units move on to, as a
// fraction of the force range; settled states (interior(j, j) = 1) weigh 0.
TEST(EstimationFilterModel, TransitWeightsAreTheForceStepToTheNextState) {
  estimation::FilterModel f = estimation::FilterModel::TwoState(60, 0.5, 0.45, 0.3);
  EXPECT_EQ(f.TransitWeights(), Eigen::Vector2d::Zero());
  f.broadcast = estimation::BroadcastTransitionModel::HeatingChain(6, 0.5);
  f.state_names = f.broadcast.state_names;
  // HeatingChain(6): 0 settled off, 1 -> 2 -> 3 heating (3 settled on), 4 -> 5 -> 0 cooling.
  f.H = Eigen::RowVectorXd(6);
  f.H << 0, 0.1, 0.3, 0.4, 0.25, 0.05;  // range 0.4
  Eigen::VectorXd expected(6);
  expected << 0, 0.2 / 0.4, 0.1 / 0.4, 0, 0.2 / 0.4, 0.05 / 0.4;
  EXPECT_LT((f.TransitWeights() - expected).cwiseAbs().maxCoeff(), 1e-15);
  // A state whose force is already its successor's weighs nothing.
  f.H(2) = 0.4;
  EXPECT_EQ(f.TransitWeights()[2], 0.0);
}

nlohmann::json GoodJson() {
  return nlohmann::json::parse(R"({
    "states": ["off", "on"], "N": 60, "H": [[0, 0.45]], "R": [[0.09]],
    "transition": {"type": "broadcast", "dt": 0.5, "is_on": [false, true],
                   "on_target": 1, "off_target": 0}})");
}

// Every class of bad field gets the words of the common checkers (common/json_fields.h), as task
// and sweep files do: the file and key, the value (shortened) and what is allowed; each is bad
// input, exit code 3.
TEST(EstimationFilterModel, ClearErrorsForBadFields) {
  ASSERT_TRUE(estimation::FilterModel::FromJsonValue(GoodJson(), "m.json").ok());
  struct Case {
    std::string pointer;  // the field replaced ("-" + pointer: removed)
    nlohmann::json value;
    std::string expected;
  };
  const auto parse = [](const char* text) { return nlohmann::json::parse(text); };
  const std::vector<Case> cases = {
      // an unknown key, at the top and inside an object
      {"/Hx", 1,
       "m.json: unknown field 'Hx'; allowed: G, H, N, Qw, R, R_transit, R_transit2, format, "
       "identification, initial, states, transition, version"},
      {"/transition/A", parse("[[1, 0], [0, 1]]"),
       "m.json.transition: unknown field 'A'; allowed: dt, interior, is_on, off_target, "
       "on_target, type"},
      {"/initial", parse(R"({"x1": [60, 0]})"),
       "m.json.initial: unknown field 'x1'; allowed: P0, x0"},
      // a required field missing
      {"-/N", nullptr, "m.json: missing field 'N' (a whole number of agents >= 1)"},
      {"-/H", nullptr, "m.json: missing field 'H' (a r x 2 matrix, an array of rows)"},
      {"-/transition", nullptr, "m.json: missing field 'transition' (an object with \"type\""},
      {"/G", parse("[[0], [0]]"), "m.json: missing field 'Qw' (G and Qw come together"},
      // a value of the wrong type or out of range
      {"/N", -3, "m.json.N: -3; allowed: a whole number of agents >= 1"},
      {"/N", 2.5, "m.json.N: 2.5; allowed: a whole number of agents >= 1"},
      {"/N", "60", "m.json.N: \"60\"; allowed: a whole number of agents >= 1"},
      {"/format", "recruit.task",
       "m.json.format: \"recruit.task\"; allowed: \"recruit.filter_model\""},
      {"/version", 2, "m.json.version: 2; allowed: 1 (the only version)"},
      {"/transition/type", "magic",
       "m.json.transition.type: \"magic\"; allowed: \"broadcast\", \"explicit\", \"constant\""},
      {"/states", parse(R"(["off", 3])"), "m.json.states[1]: must be a non-empty string, got 3"},
      {"/states", parse("[]"), "m.json.states: must be a non-empty array of names, got []"},
      {"/initial", 5, "m.json.initial: must be an object ({\"x0\", \"P0\"}), got 5"},
      {"/transition", "broadcast", "m.json.transition: must be an object (an object with"},
      // a matrix or vector of the wrong shape, or an entry that is not a number
      {"/H", parse("[[0, 0.45, 1]]"),
       "m.json.H[0]: must be an array of 2 numbers (row 0 of a r x 2 matrix), got [0,0.45,1]"},
      {"/H", parse("[]"), "m.json.H: must have at least one row (one per output), got none"},
      {"/H", 0.45, "m.json.H: must be an array of rows (a r x 2 matrix, row-major), got 0.45"},
      {"/R", parse("[[1, 0]]"),
       "m.json.R[0]: must be an array of 1 numbers (row 0 of a 1 x 1 matrix), got [1,0]"},
      {"/R", parse("[[0.09], [1]]"), "m.json.R: must have 1 rows (a 1 x 1 matrix), got 2"},
      {"/R", parse(R"([["a"]])"), "m.json.R[0][0]: must be a finite number, got \"a\""},
      {"/initial", parse(R"({"x0": [60]})"), "m.json.initial.x0: must have 2 entries, got 1"},
      {"/initial", parse(R"({"x0": [60, null]})"),
       "m.json.initial.x0[1]: must be a finite number, got null"},
      // values that are each allowed but not together, or not as a matrix
      {"/R", parse("[[-1]]"), "m.json.R: must be positive definite"},
      {"/R_transit", parse("[[-0.5]]"), "m.json.R_transit: must be positive semi-definite"},
      {"/R_transit", parse("[[1, 0]]"),
       "m.json.R_transit[0]: must be an array of 1 numbers (row 0 of a 1 x 1 matrix)"},
      {"/R_transit", "0.5", "m.json.R_transit: must be an array of rows"},
      {"/R_transit2", parse("[[-0.5]]"), "m.json.R_transit2: must be positive semi-definite"},
      {"/R_transit2", parse(R"([["x"]])"),
       "m.json.R_transit2[0][0]: must be a finite number, got \"x\""},
      {"/initial", parse(R"({"x0": [50, 9]})"),
       "m.json.initial.x0: must sum to N = 60, sums to 59"},
      {"/states", parse(R"(["off", "off"])"), "m.json.states: duplicate name 'off'"},
      // the broadcast transition's own fields
      {"/transition/interior", parse("[[0.9, 0], [0.2, 1]]"),
       "m.json.transition.interior: column 0 sums to 1.1"},
      {"/transition/interior", parse("[[0.9, 0]]"),
       "m.json.transition.interior: must have 2 rows (a 2 x 2 matrix), got 1"},
      {"/transition/dt", 0,
       "m.json.transition.dt: 0 is out of range; allowed: the sampling period in seconds, a "
       "number > 0"},
      {"/transition/dt", "0.5",
       "m.json.transition.dt: must be a number (the sampling period in seconds, a number > 0), "
       "got \"0.5\""},
      {"-/transition/dt", nullptr,
       "m.json.transition: missing field 'dt' (the sampling period in seconds, a number > 0)"},
      {"/transition/is_on", parse("[false]"),
       "m.json.transition.is_on: [false]; allowed: an array of 2 booleans (the heater command in "
       "each state)"},
      {"/transition/is_on", parse("[false, 1]"),
       "m.json.transition.is_on[1]: 1; allowed: true or false"},
      {"-/transition/is_on", nullptr,
       "m.json.transition: missing field 'is_on' (an array of 2 booleans"},
      {"/transition/on_target", 1.5,
       "m.json.transition.on_target: 1.5; allowed: a state index, or an array of 2 state "
       "indices (-1 where unused)"},
      {"/transition/off_target", parse("[-1, \"0\"]"),
       "m.json.transition.off_target[1]: \"0\"; allowed: a state index, or an array of 2"},
      {"/transition/on_target", parse("[1]"), "m.json.transition.on_target: [1]; allowed:"},
      {"/transition/on_target", 2,
       "m.json.transition.on_target[0] = 2 (state 'off', off) must be a state index in [0, 1]"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.pointer + " " + c.value.dump());
    nlohmann::json j = GoodJson();
    if (c.pointer[0] == '-') {
      const nlohmann::json::json_pointer field(c.pointer.substr(1));
      j[field.parent_pointer()].erase(field.back());
    } else {
      j[nlohmann::json::json_pointer(c.pointer)] = c.value;
    }
    auto f = estimation::FilterModel::FromJsonValue(j, "m.json");
    ASSERT_FALSE(f.ok());
    EXPECT_NE(f.error().find(c.expected), std::string::npos) << f.error();
    EXPECT_EQ(exit_code::Of(f.failure()), exit_code::kBadInput) << f.error();
  }
  nlohmann::json j = GoodJson();
  j["G"] = nlohmann::json::parse("[[1], [0]]");
  j["Qw"] = nlohmann::json::parse("[[0.5]]");
  auto f = estimation::FilterModel::FromJsonValue(j, "m.json");
  ASSERT_FALSE(f.ok());
  EXPECT_NE(f.error().find("m.json.G, Qw: G Qw G^T must have zero column sums"), std::string::npos)
      << f.error();
  EXPECT_EQ(exit_code::Of(f.failure()), exit_code::kBadInput);
}

// R_transit needs the broadcast model's interior to say which states are in transit.
TEST(EstimationFilterModel, TransitNoiseNeedsABroadcastTransition) {
  nlohmann::json j = GoodJson();
  j["R_transit"] = nlohmann::json::parse("[[0.5]]");
  ASSERT_TRUE(estimation::FilterModel::FromJsonValue(j, "m.json").ok());
  j["transition"] = nlohmann::json::parse(R"({"type": "constant", "A": [[1, 0], [0, 1]]})");
  auto f = estimation::FilterModel::FromJsonValue(j, "m.json");
  ASSERT_FALSE(f.ok());
  EXPECT_NE(f.error().find("m.json.R_transit: needs a \"broadcast\" transition"), std::string::npos)
      << f.error();
  j["R_transit"] = nlohmann::json::parse("[[0]]");  // zero: no transit noise, any transition
  EXPECT_TRUE(estimation::FilterModel::FromJsonValue(j, "m.json").ok());
}

// The optional fields, given as identify writes them, are accepted and read: format, version,
// an explicit initial belief and the identification record (its held-out R^2).
TEST(EstimationFilterModel, OptionalFieldsAreRead) {
  nlohmann::json j = GoodJson();
  j["format"] = "recruit.filter_model";
  j["version"] = 1;
  j["initial"] = nlohmann::json::parse(R"({"x0": [50, 10], "P0": [[1, -1], [-1, 1]]})");
  j["identification"] = nlohmann::json::parse(R"({"holdout": {"r2": 0.75}, "dT": 0.5})");
  auto f = estimation::FilterModel::FromJsonValue(j, "m.json");
  ASSERT_TRUE(f.ok()) << f.error();
  EXPECT_EQ(f->x0, Eigen::Vector2d(50, 10));
  EXPECT_EQ(f->P0, (Eigen::Matrix2d{{1, -1}, {-1, 1}}));
  EXPECT_EQ(f->holdout_r2, 0.75);
  EXPECT_TRUE(std::isnan(estimation::FilterModel::FromJsonValue(GoodJson(), "m.json")->holdout_r2));
}

TEST(EstimationFilterModel, MissingAndMalformedFiles) {
  auto missing = estimation::FilterModel::FromJson("/nonexistent/dir/model.json");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().find("/nonexistent/dir/model.json"), std::string::npos);
  // A path that names no file is bad input (common/result.h, CodeOf); the CLI's own check of
  // --model says usage (2) first.
  EXPECT_EQ(exit_code::Of(missing.failure()), exit_code::kBadInput);
  const std::string path = testing::TempDir() + "/estimation_malformed.json";
  std::ofstream(path) << "{\"states\": [\"off\", ";
  auto bad = estimation::FilterModel::FromJson(path);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().find(path + ": not valid JSON"), std::string::npos) << bad.error();
  EXPECT_EQ(exit_code::Of(bad.failure()), exit_code::kBadInput);
  std::remove(path.c_str());
}

// Issue 12 regressions: JSON that nlohmann rejects with something other than a parse error,
// or that is dangerous to build a tree from, gives a clear error naming the file and field.
std::string WriteTemp(const std::string& name, const std::string& text) {
  const std::string path = testing::TempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

TEST(EstimationFilterModel, NumberTooLargeForADoubleNamesTheFile) {
  const std::string path =
      WriteTemp("estimation_overflow.json",
                R"({"states": ["off", "on"], "N": 60, "H": [[0, 1e999]], "R": [[0.09]],
          "transition": {"type": "explicit"}})");
  auto f = estimation::FilterModel::FromJson(path);
  ASSERT_FALSE(f.ok());
  EXPECT_NE(f.error().find(path + ": a number is too large for a double"), std::string::npos)
      << f.error();
  EXPECT_EQ(exit_code::Of(f.failure()), exit_code::kBadInput);
  std::remove(path.c_str());
}

TEST(EstimationFilterModel, DeepNestingIsRejectedBeforeRecursion) {
  const int depth = 70000;
  const std::string path =
      WriteTemp("estimation_deep.json",
                R"({"states": )" + std::string(depth, '[') + std::string(depth, ']') + "}");
  auto f = estimation::FilterModel::FromJson(path);
  ASSERT_FALSE(f.ok());
  EXPECT_NE(f.error().find(path + ": arrays/objects nested more than 128 deep"), std::string::npos)
      << f.error();
  EXPECT_EQ(exit_code::Of(f.failure()), exit_code::kBadInput);
  std::remove(path.c_str());
}

// A 2 MB value comes back shortened to about 40 characters, in every kind of message.
TEST(EstimationFilterModel, LongValuesAreShortenedInMessages) {
  const std::string big(2000000, 'x');
  const std::vector<std::string> docs = {
      R"({"states": ["off", "on"], "N": 60, "H": [[0, 0.45]], "R": [[0.09]],
          "transition": {"type": ")" +
          big + R"("}})",
      R"({"states": [")" + big + R"(", ")" + big + R"("], "N": 60, "H": [[0, 0.45]],
          "R": [[0.09]], "transition": {"type": "explicit"}})",
      R"({"states": ["off", "on"], "N": 60, "H": [[0, 1)" + std::string(400, '0') + "e999]]}",
      R"({"states": ["off", "on"], "N": 60, "H": [[0, )" + big + "]]}",
      R"({")" + big + R"(": [[)" + std::string(100, '[') + "1e999",
  };
  for (size_t i = 0; i < docs.size(); ++i) {
    SCOPED_TRACE(i);
    const std::string path = WriteTemp("estimation_long.json", docs[i]);
    auto f = estimation::FilterModel::FromJson(path);
    ASSERT_FALSE(f.ok());
    EXPECT_LT(f.error().size(), 400u) << f.error().substr(0, 400);
    std::remove(path.c_str());
  }
}

// The file reader (1 MiB chunks, lines cut at chunk boundaries) gives the same output as the
// in-memory text, for a log of about 3 MB with a byte-order mark, comments and blank lines.
TEST(EstimationFilterLog, FileStreamMatchesInMemoryText) {
  const estimation::FilterModel f = estimation::FilterModel::TwoState(60, 0.5, 0.45, 0.3);
  std::string text = "\xEF\xBB\xBFt,p_on,p_off,y\n# a comment\n";
  for (int k = 0; k < 100000; ++k) {
    text += std::to_string(0.5 * k) + "," + std::to_string(0.001 * (k % 300)) + "," +
            std::to_string(0.001 * (k % 200)) + "," +
            (k % 9 == 4 ? std::string() : std::to_string(13.0 + 5.0 * std::sin(0.01 * k))) +
            (k % 1000 == 7 ? "\n\n" : "\n");
  }
  const std::string path = WriteTemp("estimation_stream_log.csv", text);
  auto a = estimation::MakeCountFilter(f, {});
  auto b = estimation::MakeCountFilter(f, {});
  ASSERT_TRUE(a.ok() && b.ok());
  auto in_memory = estimation::RunFilterOverText(f, text, path, **a);
  ASSERT_TRUE(in_memory.ok()) << in_memory.error();
  auto reader = estimation::FilterLogReader::OpenFile(path, f);
  ASSERT_TRUE(reader.ok()) << reader.error();
  std::ostringstream out;
  const Status s = estimation::RunFilterStream(f, **reader, **b, out);
  ASSERT_TRUE(s.ok()) << s.error();
  const std::string streamed = out.str();
  EXPECT_EQ(streamed, *in_memory);
  EXPECT_EQ(std::count(streamed.begin(), streamed.end(), '\n'), 100001);
  std::remove(path.c_str());
}

}  // namespace file_filter_model_test
}  // namespace recruit
