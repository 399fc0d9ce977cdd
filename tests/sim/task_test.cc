// Task files: a good file parses to the values it states; each kind of bad file gives an error
// that names the file and the field.
#include "sim/task.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace recruit::sim {
namespace file_task_test {

namespace fs = std::filesystem;

class TaskFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        fs::temp_directory_path() /
        ("recruit_task_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
         "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    std::ofstream(dir_ / "bench.xml") << "<mujoco/>";
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Write(const std::string& text) {
    const std::string path = (dir_ / "task.json").string();
    std::ofstream(path) << text;
    return path;
  }
  // A valid force task; `extra` is spliced in as additional fields.
  std::string Force(const std::string& extra = "") {
    return R"({"name": "t", "model": "bench.xml", "tracked": "force", "agonist": "bundle",
               "duration": 20, "reference": {"type": "steps", "times": [1], "values": [10]})" +
           extra + "}";
  }
  std::string Angle(const std::string& outer, const std::string& extra = "") {
    return R"({"name": "a", "model": "bench.xml", "tracked": "angle", "agonist": "flexor",
               "antagonist": "extensor", "joint": "elbow", "duration": 30,
               "reference": {"type": "steps", "times": [0, 10], "values": [30, 60]})" +
           outer + extra + "}";
  }
  // Expects an error that contains the file's path and every fragment.
  void ExpectError(const std::string& text, std::vector<std::string> fragments) {
    const std::string path = Write(text);
    auto t = Task::FromFile(path);
    ASSERT_FALSE(t.ok()) << "accepted: " << text;
    EXPECT_NE(t.error().find(path), std::string::npos) << t.error();
    for (const auto& f : fragments) EXPECT_NE(t.error().find(f), std::string::npos) << t.error();
  }

  fs::path dir_;
};

TEST_F(TaskFileTest, GoodForceTaskParses) {
  auto t = Task::FromFile(Write(Force(R"(, "controller": {"estimator": "kalman-augmented",
      "dT": 0.5, "lambda": 0.3}, "timestep": 0.002)")));
  ASSERT_TRUE(t.ok()) << t.error();
  EXPECT_EQ(t->name, "t");
  EXPECT_EQ(t->tracked, Tracked::kForce);
  EXPECT_EQ(t->model_path, (dir_ / "bench.xml").string());  // relative to the task file
  EXPECT_DOUBLE_EQ(t->duration, 20);
  EXPECT_DOUBLE_EQ(t->timestep, 0.002);
  EXPECT_EQ(t->controller.estimator, "kalman-augmented");
  EXPECT_DOUBLE_EQ(t->controller.dT, 0.5);
  EXPECT_DOUBLE_EQ(t->controller.lambda, 0.3);
  EXPECT_DOUBLE_EQ(t->reference(0.5), 0);
  EXPECT_DOUBLE_EQ(t->reference(1.5), 10);
}

TEST_F(TaskFileTest, GoodAngleTaskConvertsDegreesAndReadsPushesAndPayloads) {
  auto t = Task::FromFile(Write(Angle(R"(, "outer_loop": {"kp": 20, "ki": 5, "tone": 2})",
                                      R"(, "pushes": [{"body": "hand", "start": 12, "duration": 0.5,
                                           "force": [0, 0, -3]}],
                                         "payloads": [{"body": "payload", "mass": 0.2, "time": 5}])")));
  ASSERT_TRUE(t.ok()) << t.error();
  EXPECT_EQ(t->tracked, Tracked::kAngle);
  EXPECT_NEAR(t->reference(5), M_PI / 6, 1e-12);
  EXPECT_NEAR(t->reference(15), M_PI / 3, 1e-12);
  ASSERT_TRUE(t->outer.has_value());
  EXPECT_DOUBLE_EQ(t->outer->kp, 20);
  EXPECT_DOUBLE_EQ(t->outer->tone, 2);
  ASSERT_EQ(t->pushes.size(), 1u);
  EXPECT_DOUBLE_EQ(t->pushes[0].force.z(), -3);
  ASSERT_EQ(t->payloads.size(), 1u);
  EXPECT_DOUBLE_EQ(t->payloads[0].mass, 0.2);
}

TEST_F(TaskFileTest, MissingFileIsNamed) {
  auto t = Task::FromFile((dir_ / "nope.json").string());
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.error().find("nope.json"), std::string::npos) << t.error();
}

TEST_F(TaskFileTest, MalformedJson) { ExpectError("{\"name\": ", {"not valid JSON"}); }
TEST_F(TaskFileTest, NotAnObject) { ExpectError("[1, 2]", {"JSON object"}); }
TEST_F(TaskFileTest, MissingName) {
  ExpectError(R"({"model": "bench.xml", "tracked": "force"})", {"'name'"});
}
TEST_F(TaskFileTest, UnknownFieldListsAllowedOnes) {
  ExpectError(Force(R"(, "duraton": 3)"), {"unknown field 'duraton'", "allowed", "duration"});
}
TEST_F(TaskFileTest, MissingModelFile) {
  ExpectError(R"({"name": "t", "model": "missing.xml", "tracked": "force", "agonist": "b",
                  "duration": 1, "reference": {"type": "constant", "value": 1}})",
              {".model", "missing.xml", "does not exist"});
}
TEST_F(TaskFileTest, UnknownTracked) {
  ExpectError(R"({"name": "t", "model": "bench.xml", "tracked": "torque"})",
              {".tracked", "torque", "allowed: force, angle"});
}
TEST_F(TaskFileTest, NegativeDuration) {
  ExpectError(R"({"name": "t", "model": "bench.xml", "tracked": "force", "agonist": "b",
                  "duration": -5, "reference": {"type": "constant", "value": 1}})",
              {".duration", "out of range", "0 < duration"});
}
TEST_F(TaskFileTest, DurationNotANumber) {
  ExpectError(R"({"name": "t", "model": "bench.xml", "tracked": "force", "agonist": "b",
                  "duration": "long"})",
              {".duration", "must be a number"});
}
TEST_F(TaskFileTest, BadReferenceType) {
  ExpectError(R"({"name": "t", "model": "bench.xml", "tracked": "force", "agonist": "b",
                  "duration": 5, "reference": {"type": "sine"}})",
              {".reference.type", "sine", "paper_fig5"});
}
TEST_F(TaskFileTest, NegativeForceReference) {
  ExpectError(R"({"name": "t", "model": "bench.xml", "tracked": "force", "agonist": "b",
                  "duration": 5, "reference": {"type": "constant", "value": -2}})",
              {".reference", ">= 0 N"});
}
TEST_F(TaskFileTest, WrongReferenceUnit) {
  ExpectError(R"({"name": "t", "model": "bench.xml", "tracked": "force", "agonist": "b",
                  "duration": 5, "reference": {"type": "constant", "value": 2, "unit": "deg"}})",
              {".reference.unit", "allowed: N"});
}
TEST_F(TaskFileTest, LambdaOutOfRange) {
  ExpectError(Force(R"(, "controller": {"lambda": 1.5})"),
              {".controller.lambda", "0 < lambda <= 1"});
}
TEST_F(TaskFileTest, ZeroDt) {
  ExpectError(Force(R"(, "controller": {"dT": 0})"), {".controller.dT", "0 < dT"});
}
TEST_F(TaskFileTest, AngleTaskWithoutOuterLoop) { ExpectError(Angle(""), {"'outer_loop'"}); }
TEST_F(TaskFileTest, AngleTaskWithoutJoint) {
  ExpectError(R"({"name": "a", "model": "bench.xml", "tracked": "angle", "agonist": "f",
                  "duration": 5, "reference": {"type": "constant", "value": 1},
                  "outer_loop": {"kp": 1}})",
              {"'joint'"});
}
TEST_F(TaskFileTest, NegativeGain) {
  ExpectError(Angle(R"(, "outer_loop": {"kp": -1})"), {".outer_loop.kp", ">= 0"});
}
TEST_F(TaskFileTest, ToneAboveMaxForce) {
  ExpectError(Angle(R"(, "outer_loop": {"kp": 1, "tone": 40, "max_force": 30})"),
              {".outer_loop.tone", "max_force"});
}
TEST_F(TaskFileTest, OuterLoopOnForceTask) {
  ExpectError(Force(R"(, "outer_loop": {"kp": 1})"), {".outer_loop", "only angle tasks"});
}
TEST_F(TaskFileTest, PushWithBadVector) {
  ExpectError(
      Angle(R"(, "outer_loop": {"kp": 1})",
            R"(, "pushes": [{"body": "hand", "start": 1, "duration": 1, "force": [1, 2]}])"),
      {".pushes[0].force", "3 numbers"});
}
TEST_F(TaskFileTest, PayloadWithoutMass) {
  ExpectError(Angle(R"(, "outer_loop": {"kp": 1})", R"(, "payloads": [{"body": "payload"}])"),
              {".payloads[0]", "'mass'"});
}
TEST_F(TaskFileTest, SameAgonistAndAntagonist) {
  ExpectError(R"({"name": "t", "model": "bench.xml", "tracked": "force", "agonist": "b",
                  "antagonist": "b", "duration": 5, "reference": {"type": "constant", "value": 1}})",
              {".antagonist", "must differ"});
}

}  // namespace file_task_test
}  // namespace recruit::sim
