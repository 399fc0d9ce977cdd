// Short closed-loop runs through the real plant (SMA plugin on the isometric bench and the elbow
// arm) and controller: the CSV and the summary agree with each other, the loop tracks, runs are
// reproducible per seed, a real sweep gives byte-identical reports on 1 and 2 threads, and task
// fields that do not match the model are reported by name.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/atomic_file.h"
#include "plugin/sma_host.h"
#include "sim/csv_writer.h"
#include "sim/plant.h"
#include "sim/run_task.h"
#include "sweep/grid.h"
#include "sweep/table.h"
#include "tests/plugin/mujoco_util.h"

namespace recruit::sim {
namespace file_closed_loop_test {

namespace fs = std::filesystem;
using namespace ::recruit::sweep;  // NOLINT: the sweep code under test (src/sweep)
const std::string kRoot = RECRUIT_SOURCE_DIR;

Task LoadTask(const std::string& name) {
  auto t = Task::FromFile(kRoot + "/models/tasks/" + name);
  EXPECT_TRUE(t.ok()) << t.error();
  return *t;
}

std::vector<std::vector<std::string>> ReadCsv(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::vector<std::string>> rows;
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> row;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) row.push_back(cell);
    if (!line.empty() && line.back() == ',') row.push_back("");
    rows.push_back(row);
  }
  return rows;
}

// Records what the controller saw at each control instant.
class InstantRecorder : public ControlInstantHook {
 public:
  bool Replaces() const override { return false; }
  Status OnInstant(ControlInstant& instant) override {
    times.push_back(instant.time);
    references.push_back(instant.reference);
    return Status::Ok();
  }
  std::vector<double> times, references;
};

TEST(ClosedLoop, ControlInstantsRunOnTheControllersClockAndSeeAStepAtItsTime) {
  // isometric_steps steps to 12, 24 and 8 N at 5, 20 and 35 s; MuJoCo's accumulated time after
  // 2500 steps of 2 ms is 4.999999999999671, so an instant read at the plant's time would see
  // each step one period late.
  Task task = LoadTask("isometric_steps.json");
  RunOptions o;
  o.duration = 36;
  o.dT = 1;
  InstantRecorder rec;
  o.control_hook = &rec;
  auto r = RunTask(task, o, {});
  ASSERT_TRUE(r.ok()) << r.error();
  ASSERT_EQ(rec.times.size(), 36u);
  for (size_t k = 0; k < rec.times.size(); ++k) {
    EXPECT_EQ(rec.times[k], static_cast<double>(k));
    const double expected = k < 5 ? 0 : k < 20 ? 12 : k < 35 ? 24 : 8;
    EXPECT_EQ(rec.references[k], expected) << "instant at " << k << " s";
  }
}

TEST(ClosedLoop, SimulateWritesCsvWhoseSignalsReproduceTheSummary) {
  const fs::path dir = fs::temp_directory_path() / "recruit_closed_loop_csv";
  fs::create_directories(dir);
  const std::string csv = (dir / "steps.csv").string();
  Task task = LoadTask("isometric_steps.json");
  RunOptions o;
  o.duration = 30;
  o.dT = 0.5;
  CsvStepWriter writer(csv);
  auto r = RunTask(task, o, {&writer});
  ASSERT_TRUE(r.ok()) << r.error();
  EXPECT_FALSE(fs::exists(csv)) << "the CSV appears only on Commit";
  ASSERT_TRUE(writer.Commit().ok());
  const auto rows = ReadCsv(csv);
  ASSERT_GT(rows.size(), 1u);
  const auto& h = rows[0];
  auto col = [&](const std::string& name) {
    const auto it = std::find(h.begin(), h.end(), name);
    EXPECT_NE(it, h.end()) << name;
    return static_cast<int>(it - h.begin());
  };
  const int t_col = col("time"), r_col = col("reference"), y_col = col("measured");
  const int on_col = col("bundle.true_on"), est_col = col("bundle.estimated_on");
  const int instant_col = col("control_instant");
  col("bundle.p_on");
  col("bundle.p_off");
  col("angle");
  // One row per physics step.
  EXPECT_EQ(static_cast<long>(rows.size()) - 1, r->physics_steps);
  EXPECT_EQ(r->control_instants, 60);
  // Tracking RMSE recomputed from the written signals equals the summary's.
  double se = 0;
  for (size_t k = 1; k < rows.size(); ++k) {
    const double e = std::stod(rows[k][y_col]) - std::stod(rows[k][r_col]);
    se += e * e;
  }
  EXPECT_NEAR(std::sqrt(se / (rows.size() - 1)), r->metrics.tracking_rmse,
              1e-6 * (1 + r->metrics.tracking_rmse));
  EXPECT_NEAR(std::stod(rows.back()[t_col]), 30.0, 1e-9);
  // The loop tracks: at the end of the 12 N hold (t = 19.9 s) and of the 24 N ramp-up
  // (t = 30 s) the force is within 15 % of the reference.
  for (double t_check : {19.9, 29.99}) {
    const size_t k = static_cast<size_t>(std::lround(t_check / 0.002));
    ASSERT_LT(k, rows.size());
    const double ref = std::stod(rows[k][r_col]), y = std::stod(rows[k][y_col]);
    EXPECT_NEAR(y, ref, 0.15 * ref) << "t = " << t_check;
  }
  // Output-only estimate: the on-count a settled bundle shows is the true count; at the end of
  // the 12 N hold the estimate is within 2 units of the truth.
  int k_last = -1;
  for (size_t k = 1; k < rows.size(); ++k) {
    if (std::stod(rows[k][t_col]) < 19.95 && !rows[k][est_col].empty() &&
        rows[k][instant_col] == "1") {
      k_last = static_cast<int>(k);
    }
  }
  ASSERT_GT(k_last, 0);
  EXPECT_NEAR(std::stod(rows[k_last][est_col]), std::stod(rows[k_last][on_col]), 2.0);
  fs::remove_all(dir);
}

TEST(ClosedLoop, SameSeedSameRunOtherSeedOtherRun) {
  Task task = LoadTask("isometric_steps.json");
  RunOptions o;
  o.duration = 20;
  o.dT = 0.5;
  o.seed = 5;
  auto a = RunTask(task, o), b = RunTask(task, o);
  o.seed = 6;
  auto c = RunTask(task, o);
  ASSERT_TRUE(a.ok() && b.ok() && c.ok());
  auto strip = [](nlohmann::json j) {
    j.erase("wall_seconds");
    j.erase("seed");
    return j.dump();
  };
  EXPECT_EQ(strip(a->ToJson()), strip(b->ToJson()));
  EXPECT_NE(strip(a->ToJson()), strip(c->ToJson()));
}

TEST(ClosedLoop, RealSweepIsByteIdenticalOnOneAndTwoThreads) {
  Task task = LoadTask("isometric_steps.json");
  SweepSpec spec;
  spec.dTs = {0.5, 1.0};
  spec.lambdas = {0.2};
  spec.estimators = {"output"};
  spec.seeds = 3;
  spec.duration = 12;
  auto grid = ExpandGrid(spec);
  ASSERT_TRUE(grid.ok());
  auto run = [&](const SweepRun& g) {
    RunOptions o;
    o.estimator = g.estimator;
    o.dT = g.dT;
    o.lambda = g.lambda;
    o.seed = g.seed;
    o.duration = spec.duration;
    return RunTask(task, o);
  };
  std::string reports[2];
  for (int threads : {1, 2}) {
    const fs::path dir =
        fs::temp_directory_path() / ("recruit_real_sweep_" + std::to_string(threads));
    fs::remove_all(dir);
    auto out = RunSweep(*grid, dir.string(), run, threads);
    ASSERT_TRUE(out.ok()) << out.error();
    EXPECT_EQ(out->executed, 6);
    const TrackingCriterion crit;
    ASSERT_TRUE(WriteTables(Aggregate(out->runs, crit), crit, dir.string(), "t").ok());
    reports[threads - 1] = *ReadFile((dir / "table.csv").string()) +
                           *ReadFile((dir / "table.md").string()) +
                           *ReadFile((dir / "stability.dat").string());
    fs::remove_all(dir);
  }
  EXPECT_EQ(reports[0], reports[1]);
}

TEST(ClosedLoop, ArmLiftsTowardTheReferenceAngle) {
  Task task = LoadTask("arm_reach_hold.json");
  EXPECT_TRUE(task.auto_loop) << "the shipped arm tasks run the self-tuned loop";
  RunOptions o;
  o.duration = 28;  // the 20 deg step at 10 s, held to 30 s
  auto r = RunTask(task, o);
  ASSERT_TRUE(r.ok()) << r.error();
  EXPECT_EQ(r->unit, "rad");
  ASSERT_EQ(r->steps.size(), 1u);
  // One design per reference reached: the start (0 deg, kept 3 % of the range inside the limit)
  // and 20 deg.
  ASSERT_EQ(r->loop_designs.size(), 2u);
  EXPECT_NEAR(r->loop_designs[1]["reference"].get<double>(), 20 * M_PI / 180, 1e-12);
  // It reaches the 20 deg band (the overshoot is > -1, i.e. the step was completed in part) and
  // does not run away past twice the step.
  EXPECT_LT(r->metrics.max_overshoot, 1.0);
  EXPECT_LT(r->metrics.tracking_rmse, 20 * M_PI / 180);
}

TEST(ClosedLoop, ArmScoresEveryBundleAndKeepsItsUnitsWithinTheirLimits) {
  Task task = LoadTask("arm_reach_hold.json");
  RunOptions o;
  o.duration = 28;
  auto r = RunTask(task, o);
  ASSERT_TRUE(r.ok()) << r.error();
  ASSERT_EQ(r->bundles.size(), 2u);
  EXPECT_EQ(r->bundles[0].actuator, "flexor");
  EXPECT_EQ(r->bundles[1].actuator, "extensor");
  EXPECT_EQ(r->metrics.estimator_rmse, r->bundles[0].estimator_rmse);
  for (const BundleSummary& b : r->bundles) {
    // Both bundles recruit (the extensor carries the tone), so both have heated units, within
    // the datasheet limits of their 0.1 mm wire (120 C, 172 MPa).
    EXPECT_GT(b.peak_temperature, 68.0) << b.actuator;  // above As: units did transform
    EXPECT_LE(b.peak_temperature, b.max_temperature) << b.actuator;
    EXPECT_GT(b.peak_wire_stress, 0.0) << b.actuator;
    EXPECT_LE(b.peak_wire_stress, b.max_wire_stress) << b.actuator;
    // The task's Kalman filter on each bundle's own length-aware model: a variance for each
    // bundle that its count errors agree with (28 s, 28 instants: a loose band).
    EXPECT_GT(b.mean_nees, 0.1) << b.actuator;
    EXPECT_LT(b.mean_nees, 5.0) << b.actuator;
  }
  // The flexor's count is close to the truth: a hot unit adds 0.7-0.9 N at these poses. The
  // extensor's is not held to it: near the hanging pose a hot extensor unit pulls 0.06-0.1 N
  // (models/elbow_arm.xml), and the self-tuned loop recruits 20 or more of them there to hold
  // the start pose against the flexor's co-contraction floor, so its count is weakly observed
  // while they heat (errors up to 10 units, which the filter's variance reports: NEES above).
  EXPECT_LT(r->bundles[0].estimator_rmse, 2.0);
  EXPECT_TRUE(r->warnings.empty());
  const nlohmann::json j = r->ToJson();
  EXPECT_EQ(j["bundles"].size(), 2u);
  EXPECT_TRUE(j["warnings"].is_array());
}

TEST(ClosedLoop, TheControllerReadsTheSeededLoadCell) {
  Task task = LoadTask("isometric_steps.json");
  RunOptions o;
  o.duration = 20;
  o.dT = 0.5;
  o.estimator = "output";
  task.sensor = {0, 0};
  auto exact = RunTask(task, o);
  task.sensor = {0.3, 0.05};
  auto noisy = RunTask(task, o), again = RunTask(task, o);
  ASSERT_TRUE(exact.ok() && noisy.ok() && again.ok());
  // The output-only count is the sensor reading over the unit force, so the sensor's noise
  // shows in the count error; the same seed reproduces the run exactly.
  EXPECT_NE(exact->metrics.estimator_rmse, noisy->metrics.estimator_rmse);
  EXPECT_EQ(noisy->metrics.estimator_rmse, again->metrics.estimator_rmse);
  EXPECT_EQ(noisy->metrics.tracking_rmse, again->metrics.tracking_rmse);
  EXPECT_EQ(noisy->ToJson()["sensor"]["noise_std"], 0.3);
}

TEST(ClosedLoop, TaskFieldsThatDoNotMatchTheModelAreNamed) {
  Task task = LoadTask("isometric_steps.json");
  task.agonist = "biceps";
  auto r = RunTask(task, {});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("isometric_steps.json.agonist"), std::string::npos) << r.error();
  EXPECT_NE(r.error().find("bundles: bundle"), std::string::npos) << r.error();

  Task arm = LoadTask("arm_push.json");
  arm.pushes[0].body = "nose";
  r = RunTask(arm, {});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("pushes[0].body"), std::string::npos) << r.error();

  arm = LoadTask("arm_push.json");
  arm.joint = "knee";
  r = RunTask(arm, {});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find(".joint: no joint 'knee'"), std::string::npos) << r.error();

  RunOptions bad;
  bad.estimator = "psychic";
  r = RunTask(LoadTask("isometric_steps.json"), bad);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("controller.estimator"), std::string::npos) << r.error();
}

// A run that draws nothing loads the model with 1-pixel builtin textures and without cameras and
// lights: the same physics step for step (against the model as mj_loadXML gives it), far fewer
// texture bytes, nothing for MuJoCo to place at each step.
TEST(ClosedLoop, PlantThatIsNotDrawnStepsLikeTheFullModel) {
  const Task task = LoadTask("arm_push.json");
  auto full = Plant::Create(task, /*drawn=*/true);
  auto bare = Plant::Create(task, /*drawn=*/false);
  ASSERT_TRUE(full.ok() && bare.ok());
  Plant& a = **full;
  Plant& b = **bare;
  EXPECT_GT(a.model()->ntexdata, 100000);
  EXPECT_LT(b.model()->ntexdata, 100);
  EXPECT_EQ(a.model()->ntex, b.model()->ntex);
  EXPECT_GE(a.model()->ncam, 1);
  EXPECT_GE(a.model()->nlight, 1);
  EXPECT_EQ(b.model()->ncam, 0);
  EXPECT_EQ(b.model()->nlight, 0);
  a.Reset(5);
  b.Reset(5);
  for (int step = 0; step < 3000; ++step) {
    if (step % 500 == 0) {
      ASSERT_TRUE(a.Broadcast(0, 0.3, 0.05).ok());
      ASSERT_TRUE(b.Broadcast(0, 0.3, 0.05).ok());
    }
    a.Step();
    b.Step();
  }
  EXPECT_GT(a.OnCount(0), 0);
  EXPECT_EQ(a.OnCount(0), b.OnCount(0));
  EXPECT_EQ(a.angle(), b.angle());
  EXPECT_EQ(a.angular_velocity(), b.angular_velocity());
  EXPECT_EQ(a.Force(0), b.Force(0));
  EXPECT_EQ(a.Force(1), b.Force(1));
  EXPECT_EQ(a.MeanTemperature(0), b.MeanTemperature(0));
}

// Steps `task`'s plant and the model as mj_loadXML gives it (every stage on) side by side,
// driven the same way: every flexor unit on, so the elbow flexes onto its upper limit (100 deg),
// then off. Every acceleration, position, velocity and force is equal, at every step: those on
// the limit and those clear of it (which the plant may step without the constraint stage).
void ExpectStepsLikeTheModelWithEveryStage(const Task& task) {
  auto created = Plant::Create(task, /*drawn=*/false);
  ASSERT_TRUE(created.ok()) << created.error();
  Plant& plant = **created;
  char error[500] = "";
  mjModel* m = mj_loadXML(task.model_path.c_str(), nullptr, error, sizeof error);
  ASSERT_NE(m, nullptr) << error;
  const int skippable = mjDSBL_FRICTIONLOSS | mjDSBL_EQUALITY | mjDSBL_ISLAND | mjDSBL_SENSOR;
  EXPECT_EQ(m->opt.disableflags & skippable, 0);
  auto host = sma::SmaHost::Create(m);
  ASSERT_TRUE(host.ok()) << host.error();
  mjData* d = mj_makeData(m);
  mj_resetData(m, d);
  (*host)->Reset(d, 5);
  mj_forward(m, d);
  plant.Reset(5);
  int limited_steps = 0, clear_steps = 0;
  for (int step = 0; step < 5000; ++step) {
    if (step == 0 || step == 3000) {
      const double p_on = step == 0 ? 1.0 : 0.0, p_off = 1.0 - p_on;
      ASSERT_TRUE(plant.Broadcast(0, p_on, p_off).ok());
      ASSERT_TRUE((*host)->Broadcast(d, plant.bundle_index(0), p_on, p_off).ok());
    }
    plant.Step();
    mj_step(m, d);
    limited_steps += d->nl > 0;
    clear_steps += d->nl == 0;
    for (int k = 0; k < m->nv; ++k) {
      ASSERT_EQ(plant.data()->qacc[k], d->qacc[k]) << "step " << step;
      ASSERT_EQ(plant.data()->qfrc_constraint[k], d->qfrc_constraint[k]) << "step " << step;
    }
  }
  EXPECT_GT(limited_steps, 0) << "no limit acted: the constraint stages went untested";
  EXPECT_GT(clear_steps, 0) << "always on a limit: the steps without constraints went untested";
  // The plant skipped the stage at exactly the steps where it made no limit row.
  EXPECT_EQ(plant.constraint_stages_skipped(),
            plant.skips_constraints_off_limits() ? clear_steps : 0);
  for (int k = 0; k < m->nq; ++k) EXPECT_EQ(plant.data()->qpos[k], d->qpos[k]);
  for (int k = 0; k < m->nv; ++k) EXPECT_EQ(plant.data()->qvel[k], d->qvel[k]);
  for (int i = 0; i < plant.num_bundles(); ++i) {
    EXPECT_EQ(plant.Force(i), (*host)->Force(d, plant.bundle_index(i)));
  }
  mj_deleteData(d);
  host->reset();
  mj_deleteModel(m);
}

// The plant disables MuJoCo stages the arm has nothing for (frictionloss, equality; islands in
// one kinematic tree) and its sensors, and steps exactly as the model with every stage on.
TEST(ClosedLoop, PlantSkipsStagesTheModelHasNothingForAndStepsTheSame) {
  const Task task = LoadTask("arm_push.json");
  auto created = Plant::Create(task, /*drawn=*/false);
  ASSERT_TRUE(created.ok()) << created.error();
  const int skipped = mjDSBL_FRICTIONLOSS | mjDSBL_EQUALITY | mjDSBL_ISLAND | mjDSBL_SENSOR;
  EXPECT_EQ((*created)->model()->opt.disableflags & skipped, skipped);
  ExpectStepsLikeTheModelWithEveryStage(task);
}

// A copy of arm_push's model with `from` replaced by `to`, in a fresh temporary folder (the model
// names no file: its textures are builtin), removed with the object; `task` points at it.
struct EditedArm {
  Task task = LoadTask("arm_push.json");
  std::filesystem::path dir;
  EditedArm(const std::string& from, const std::string& to) {
    std::ifstream in(task.model_path);
    std::stringstream text;
    text << in.rdbuf();
    std::string xml = text.str();
    const size_t at = xml.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) xml.replace(at, from.size(), to);
    static int made = 0;
    dir = std::filesystem::temp_directory_path() /
          ("recruit_arm_" + std::to_string(::getpid()) + "_" + std::to_string(made++));
    std::filesystem::create_directories(dir);
    task.model_path = (dir / "elbow_arm.xml").string();
    std::ofstream(task.model_path) << xml;
  }
  ~EditedArm() { std::filesystem::remove_all(dir); }
};

// With dry friction in the elbow, the frictionloss stage stays on, and the plant still steps as
// the model with every stage on.
TEST(ClosedLoop, PlantKeepsTheFrictionlossStageOfAModelWithFriction) {
  const EditedArm arm("damping=\"0.02\"", "damping=\"0.02\" frictionloss=\"0.002\"");
  auto created = Plant::Create(arm.task, /*drawn=*/false);
  ASSERT_TRUE(created.ok()) << created.error();
  EXPECT_EQ((*created)->model()->opt.disableflags & mjDSBL_FRICTIONLOSS, 0);
  EXPECT_NE((*created)->model()->opt.disableflags & mjDSBL_EQUALITY, 0);
  ExpectStepsLikeTheModelWithEveryStage(arm.task);
}

// Clear of its limits, a step skips the constraint stage only where nothing but a hinge's or a
// slide's limit can make a row, and the integrator evaluates only the step's start; each plant
// still steps as the model with every stage on.
TEST(ClosedLoop, PlantSkipsTheConstraintStageOnlyWhereNoRowCanBeMadeOffTheLimits) {
  const Task arm = LoadTask("arm_push.json");
  auto created = Plant::Create(arm, /*drawn=*/false);
  ASSERT_TRUE(created.ok()) << created.error();
  EXPECT_TRUE((*created)->skips_constraints_off_limits());
  created = Plant::Create(LoadTask("isometric_paper.json"), /*drawn=*/false);  // no limit at all
  ASSERT_TRUE(created.ok()) << created.error();
  EXPECT_TRUE((*created)->skips_constraints_off_limits());

  struct Case {
    const char* what;
    std::string from, to;
    bool skips;
  };
  const Case cases[] = {
      {"implicitfast integrator", "integrator=\"Euler\"", "integrator=\"implicitfast\"", true},
      {"RK4 evaluates mid-step states", "integrator=\"Euler\"", "integrator=\"RK4\"", false},
      {"contacts on: the floor can collide", "<flag contact=\"disable\"/>", "", false},
      {"a tendon limit", "<spatial name=\"flexor\"",
       "<spatial name=\"flexor\" limited=\"true\" range=\"0.2 0.35\"", false},
      {"qpos0 within the elbow's margin", "damping=\"0.02\"", "damping=\"0.02\" margin=\"0.01\"",
       false},
      {"a margin, qpos0 clear of it", "range=\"0 100\" damping=\"0.02\"",
       "range=\"-10 100\" damping=\"0.02\" margin=\"0.05\"", true},
      {"dry friction", "damping=\"0.02\"", "damping=\"0.02\" frictionloss=\"0.002\"", false},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    // Captured, not logged to MUJOCO_LOG.TXT in the working folder: the wider range makes the
    // plugin's fit check warn. Nothing else may warn (a bad state, a full arena).
    const sma::testing::WarningCapture warnings;
    const EditedArm edited(c.from, c.to);
    created = Plant::Create(edited.task, /*drawn=*/false);
    ASSERT_TRUE(created.ok()) << created.error();
    EXPECT_EQ((*created)->skips_constraints_off_limits(), c.skips);
    ExpectStepsLikeTheModelWithEveryStage(edited.task);
    for (const std::string& w : warnings.texts()) {
      EXPECT_NE(w.find("recruit.sma actuator"), std::string::npos) << w;
    }
  }
}

// Island discovery stays on in a model that enables sleeping, which works on islands.
TEST(ClosedLoop, PlantKeepsIslandsWhenTheModelSleeps) {
  const EditedArm arm("<flag contact=\"disable\"/>",
                      "<flag contact=\"disable\" sleep=\"enable\"/>");
  auto created = Plant::Create(arm.task, /*drawn=*/false);
  ASSERT_TRUE(created.ok()) << created.error();
  EXPECT_NE((*created)->model()->opt.enableflags & mjENBL_SLEEP, 0);
  EXPECT_EQ((*created)->model()->opt.disableflags & mjDSBL_ISLAND, 0);
}

// A run that draws nothing keeps the cameras when a sensor names one (the model would not compile
// without it) or a custom tuple does (deleting the camera would drop the tuple), and still
// leaves out the lights.
TEST(ClosedLoop, PlantKeepsTheCamerasTheModelNames) {
  const EditedArm sensed(
      "<sensor>", "<sensor>\n    <framepos name=\"eye\" objtype=\"camera\" objname=\"render\"/>");
  auto created = Plant::Create(sensed.task, /*drawn=*/false);
  ASSERT_TRUE(created.ok()) << created.error();
  EXPECT_GE((*created)->model()->ncam, 1);
  EXPECT_EQ((*created)->model()->nlight, 0);

  const EditedArm listed("<sensor>",
                         "<custom><tuple name=\"views\"><element objtype=\"camera\" "
                         "objname=\"render\"/></tuple></custom>\n  <sensor>");
  created = Plant::Create(listed.task, /*drawn=*/false);
  ASSERT_TRUE(created.ok()) << created.error();
  EXPECT_GE((*created)->model()->ncam, 1);
  EXPECT_EQ((*created)->model()->nlight, 0);
  EXPECT_EQ((*created)->model()->ntuple, 1);
}

bool Has(const Plant& p, mjtObj type, const char* name) {
  return mj_name2id(p.model(), type, name) >= 0;
}

// A run that draws nothing leaves out the world's geoms no contact can reach (the arm's floor,
// with contacts off, and its mount) and the sites nothing names (the hand); it keeps the wrapping
// pulley, the tendons' sites and side sites. It steps as the whole model all the same
// (PlantSkipsStagesTheModelHasNothingForAndStepsTheSame).
TEST(ClosedLoop, PlantLeavesOutTheWorldGeomsAndSitesNothingReaches) {
  const Task task = LoadTask("arm_push.json");
  auto full = Plant::Create(task, /*drawn=*/true);
  auto bare = Plant::Create(task, /*drawn=*/false);
  ASSERT_TRUE(full.ok() && bare.ok());
  for (const char* geom : {"floor", "mount", "humerus", "elbow_pulley"}) {
    EXPECT_TRUE(Has(**full, mjOBJ_GEOM, geom)) << geom;
  }
  EXPECT_TRUE(Has(**full, mjOBJ_SITE, "hand"));
  EXPECT_FALSE(Has(**bare, mjOBJ_GEOM, "floor"));
  EXPECT_FALSE(Has(**bare, mjOBJ_GEOM, "mount"));
  EXPECT_FALSE(Has(**bare, mjOBJ_SITE, "hand"));
  // Geoms of a body that is not the world are part of its inertia: they stay.
  EXPECT_TRUE(Has(**bare, mjOBJ_GEOM, "humerus"));
  EXPECT_TRUE(Has(**bare, mjOBJ_GEOM, "elbow_pulley"));
  for (const char* site :
       {"flexor_origin", "under_pulley", "behind_pulley", "extensor_insertion"}) {
    EXPECT_TRUE(Has(**bare, mjOBJ_SITE, site)) << site;
  }
}

// With contacts on, the floor can collide and stays; a site a sensor names stays, and so does a
// world geom a sensor or a contact pair names (the others still go).
TEST(ClosedLoop, PlantKeepsTheGeomsAContactReachesAndTheSitesSomethingNames) {
  const EditedArm contacts("<flag contact=\"disable\"/>", "");
  auto created = Plant::Create(contacts.task, /*drawn=*/false);
  ASSERT_TRUE(created.ok()) << created.error();
  EXPECT_TRUE(Has(**created, mjOBJ_GEOM, "floor"));
  EXPECT_FALSE(Has(**created, mjOBJ_GEOM, "mount"));

  const EditedArm sensed("<sensor>",
                         "<sensor>\n    <framepos name=\"hand\" objtype=\"site\" "
                         "objname=\"hand\"/>");
  created = Plant::Create(sensed.task, /*drawn=*/false);
  ASSERT_TRUE(created.ok()) << created.error();
  EXPECT_TRUE(Has(**created, mjOBJ_SITE, "hand"));

  // A sensor on one world geom keeps that one only.
  const EditedArm framed("<sensor>",
                         "<sensor>\n    <framepos name=\"mount\" objtype=\"geom\" "
                         "objname=\"mount\"/>");
  created = Plant::Create(framed.task, /*drawn=*/false);
  ASSERT_TRUE(created.ok()) << created.error();
  EXPECT_TRUE(Has(**created, mjOBJ_GEOM, "mount"));
  EXPECT_FALSE(Has(**created, mjOBJ_GEOM, "floor"));

  const EditedArm paired(
      "<tendon>", "<contact><pair geom1=\"mount\" geom2=\"payload\"/></contact>\n  <tendon>");
  created = Plant::Create(paired.task, /*drawn=*/false);
  ASSERT_TRUE(created.ok()) << created.error();
  EXPECT_TRUE(Has(**created, mjOBJ_GEOM, "mount"));
  EXPECT_FALSE(Has(**created, mjOBJ_GEOM, "floor"));
}

// The plant's reads of a bundle (kept from one pass after each step) follow every broadcast and
// step: each equals the host's separate read of the same mjData at that moment.
TEST(ClosedLoop, PlantReadsFollowBroadcastsAndSteps) {
  const Task task = LoadTask("arm_push.json");
  auto created = Plant::Create(task, /*drawn=*/false);
  ASSERT_TRUE(created.ok()) << created.error();
  Plant& plant = **created;
  plant.Reset(11);
  const sma::SmaHost& host = plant.host();
  auto expect_fresh = [&](int i) {
    const int b = plant.bundle_index(i);
    EXPECT_EQ(plant.OnCount(i), host.OnCount(plant.data(), b));
    EXPECT_EQ(plant.Force(i), host.Force(plant.data(), b));
    EXPECT_EQ(plant.MeanTemperature(i), host.MeanTemperature(plant.data(), b));
  };
  int changed = 0;
  for (int step = 0; step < 600; ++step) {
    if (step % 100 == 0) {
      const int before = plant.OnCount(0);
      ASSERT_TRUE(plant.Broadcast(0, 0.5, 0.1).ok());
      changed += plant.OnCount(0) != before;
      expect_fresh(0);
    }
    plant.Step();
    expect_fresh(0);
    expect_fresh(1);
  }
  EXPECT_GT(changed, 0) << "no broadcast changed the on count: the test checks nothing";
}

// An observer that draws is handed the model with its textures at full size, its cameras and
// lights.
TEST(ClosedLoop, AnObserverThatDrawsGetsTheFullModel) {
  struct Drawer : StepObserver {
    int ntexdata = -1, ncam = -1, nlight = -1;
    Status OnStep(const mjModel* m, const mjData*, const TelemetrySample&) override {
      ntexdata = m->ntexdata;
      ncam = m->ncam;
      nlight = m->nlight;
      return Status::Ok();
    }
    bool Draws() const override { return true; }
  } drawer;
  const Task task = LoadTask("arm_push.json");
  RunOptions o;
  o.duration = 0.01;
  o.quiet = true;
  ASSERT_TRUE(RunTask(task, o, {&drawer}).ok());
  char error[500] = "";
  mjModel* m = mj_loadXML(task.model_path.c_str(), nullptr, error, sizeof error);
  ASSERT_NE(m, nullptr) << error;
  EXPECT_EQ(drawer.ntexdata, m->ntexdata);
  EXPECT_EQ(drawer.ncam, m->ncam);
  EXPECT_EQ(drawer.nlight, m->nlight);
  mj_deleteModel(m);
}

}  // namespace file_closed_loop_test
}  // namespace recruit::sim
