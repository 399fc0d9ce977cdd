// The exported self-tuned joint loops ("outer_loop": "auto") against the C++ loops they were
// frozen from (src/export/auto_loop_export.h): fed the control instants recorded from RunTask
// (every driven joint's reference, angle and velocity, each bundle's load cell and length) the
// package gives the same force references, broadcasts and estimates (double: to 1e-12 relative;
// float: within the bound docs/export.md states), and driving the simulated plant it gives the
// same metrics. Tasks: the elbow arm with the self-tuned loop (tests/export/data/arm_auto.json),
// the project's two-joint arm attached by `recruit attach` (six bundles, two joints) and, when
// myo-sim is installed, MyoSuite's elbow (six bundles on one joint).
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>

#include "attach/attach.h"
#include "common/step_observer.h"
#include "control/torque_allocation.h"
#include "export/controller_export.h"
#include "sim/plant.h"
#include "sim/run_task.h"
#include "sim/task.h"
#include "tests/export/float_bounds.h"
#include "tests/export/m4_build.h"
#include "tests/export/package_loader.h"

namespace recruit::exporter {
namespace file_auto_loop_test {

using testing::FloatDeviation;
using testing::FreshDir;
using testing::kFloatForceRef;
using testing::LoadedController;
using testing::M4Package;
using testing::MetricMeans;
using testing::Rel;

const std::string kSrc = RECRUIT_SOURCE_DIR;

struct AutoCase {
  std::string label;
  std::string task_file;
  std::string estimator;  // "" = the task's
  double duration;
};

sim::RunOptions Options(const AutoCase& c, std::uint64_t seed) {
  sim::RunOptions o;
  if (!c.estimator.empty()) o.estimator = c.estimator;
  o.duration = c.duration;
  o.seed = seed;
  o.quiet = true;
  return o;
}

sim::Task LoadTask(const AutoCase& c) {
  auto t = sim::Task::FromFile(c.task_file);
  EXPECT_TRUE(t.ok()) << t.error();
  return *t;
}

// The project's two-joint arm with every muscle replaced, and its starter task (written once).
std::string Arm2jTask() {
  static const std::string path = [] {
    const auto dir = FreshDir("arm2j");
    attach::AttachOptions o;
    o.model = kSrc + "/models/arm2j_muscle.xml";
    o.muscles = {"all"};
    o.output = (dir / "arm2j_sma.xml").string();
    o.task = (dir / "task.json").string();
    auto r = attach::Attach(o);
    EXPECT_TRUE(r.ok()) << r.error();
    return r.ok() ? o.task : std::string();
  }();
  return path;
}

// MyoSuite's elbow (myo-sim, a test dependency) with its six muscles replaced; "" when myo-sim
// is not installed.
std::string MyoElbowTask() {
  static const std::string path = [] {
    FILE* p = popen((kSrc + "/.venv/bin/python -c \"import myo_sim, os; "
                            "print(os.path.dirname(myo_sim.__file__))\" 2>/dev/null")
                        .c_str(),
                    "r");
    if (p == nullptr) return std::string();
    char buf[512] = {0};
    const bool read = std::fgets(buf, sizeof buf, p) != nullptr;
    pclose(p);
    std::string dir = read ? buf : "";
    while (!dir.empty() && (dir.back() == '\n' || dir.back() == '\r')) dir.pop_back();
    const std::string model = dir + "/models/legacy/elbow/myoelbow_1dof6muscles.xml";
    if (dir.empty() || !std::filesystem::exists(model)) return std::string();
    const auto out = FreshDir("myoelbow");
    attach::AttachOptions o;
    o.model = model;
    o.muscles = {"all"};
    o.output = (out / "myoelbow_sma.xml").string();
    o.task = (out / "task.json").string();
    auto r = attach::Attach(o);
    EXPECT_TRUE(r.ok()) << r.error();
    return r.ok() ? o.task : std::string();
  }();
  return path;
}

// The cases: the estimators that need no identification (output, kalman2: the loop is designed
// on the unit's thermal lag) and, on the elbow arm, the Kalman filter on its shipped models.
std::vector<AutoCase> Cases() {
  std::vector<AutoCase> cases = {
      {"arm_auto output", kSrc + "/tests/export/data/arm_auto.json", "", 40},
      {"arm_auto kalman-augmented", kSrc + "/tests/export/data/arm_auto.json", "kalman-augmented",
       40},
      {"arm2j output", Arm2jTask(), "output", 100},
      {"arm2j kalman2", Arm2jTask(), "kalman2", 60}};
  if (!MyoElbowTask().empty()) cases.push_back({"myoelbow output", MyoElbowTask(), "output", 60});
  return cases;
}

// The package for a case, compiled and loaded; `manifest`: its export.json.
std::unique_ptr<LoadedController> Load(const AutoCase& c, Precision p, const std::string& name,
                                       nlohmann::json* manifest = nullptr) {
  auto pkg = ExportController(LoadTask(c), Options(c, 1), p);
  EXPECT_TRUE(pkg.ok()) << pkg.error();
  if (!pkg.ok()) return nullptr;
  const auto dir = FreshDir(name);
  testing::WriteFiles(pkg->files, dir);
  for (const ExportedFile& f : pkg->files) {
    if (f.name == "export.json" && manifest != nullptr)
      *manifest = nlohmann::json::parse(f.contents);
  }
  auto loaded = std::make_unique<LoadedController>(dir);
  EXPECT_EQ(loaded->error(), "");
  return loaded->error().empty() ? std::move(loaded) : nullptr;
}

// The run's mjData, seen from the first physics step on (what the loops read between steps).
class DataTap : public StepObserver {
 public:
  Status OnStep(const mjModel*, const mjData* d, const TelemetrySample&) override {
    data = d;
    return Status::Ok();
  }
  const mjData* data = nullptr;
};

// One control instant as the package reads it, and what the C++ controllers decided.
struct Instant {
  std::vector<double> in;  // reference[nj], angle[nj], velocity[nj], force[nb], length[nb]
  sim::ControlInstant decided;
};

// Records each control instant; with a package, the package decides in the C++ controllers'
// place. RunTask applies the instant's broadcasts after its hook returns (ControlInstantStep),
// and refuses a replacing hook for the self-tuned loops (it would need every joint's encoder),
// so the package overwrites what the C++ controllers decided: the plant then runs on the
// package's broadcasts, and the C++ loop, which reads only the plant, sees that plant.
class AutoHook : public sim::ControlInstantHook {
 public:
  AutoHook(const sim::Task& task, std::uint64_t seed, DataTap& tap, LoadedController* package)
      : task_(task), tap_(tap), package_(package) {
    auto plant = sim::Plant::Create(task, false);
    EXPECT_TRUE(plant.ok()) << plant.error();
    (*plant)->Reset(seed);  // the limb at the first instant
    const mjModel* m = (*plant)->model();
    for (const sim::DrivenJoint& j : task.joints) {
      const int id = mj_name2id(m, mjOBJ_JOINT, j.joint.c_str());
      qadr_.push_back(m->jnt_qposadr[id]);
      dadr_.push_back(m->jnt_dofadr[id]);
      q0_.push_back((*plant)->data()->qpos[qadr_.back()]);
      v0_.push_back((*plant)->data()->qvel[dadr_.back()]);
    }
  }
  bool Replaces() const override { return false; }
  Status OnInstant(sim::ControlInstant& c) override {
    const int nj = static_cast<int>(qadr_.size()), nb = static_cast<int>(c.sensed_force.size());
    Instant k;
    for (int j = 0; j < nj; ++j) k.in.push_back(task_.joints[j].reference(c.time));
    for (int j = 0; j < nj; ++j) k.in.push_back(tap_.data ? tap_.data->qpos[qadr_[j]] : q0_[j]);
    for (int j = 0; j < nj; ++j) k.in.push_back(tap_.data ? tap_.data->qvel[dadr_[j]] : v0_[j]);
    for (int i = 0; i < nb; ++i) k.in.push_back(c.sensed_force[i]);
    for (int i = 0; i < nb; ++i) k.in.push_back(c.tendon_length[i]);
    k.decided = c;
    if (package_ != nullptr) {
      std::vector<double> out;
      package_->Step(k.in, out);
      for (int i = 0; i < nb; ++i) {
        c.force_reference[i] = out[5 * i];
        c.broadcast[i] = {out[5 * i + 1], out[5 * i + 2]};
        c.estimated_on[i] = out[5 * i + 3];
        c.estimated_on_variance[i] = out[5 * i + 4];
      }
      bool exact = false;
      package_->pose(&exact);
      inexact_poses += exact ? 0 : 1;
    }
    instants.push_back(std::move(k));
    return Status::Ok();
  }
  std::vector<Instant> instants;
  int inexact_poses = 0;

 private:
  const sim::Task& task_;
  DataTap& tap_;
  LoadedController* package_;
  std::vector<int> qadr_, dadr_;
  std::vector<double> q0_, v0_;
};

struct RecordedRun {
  sim::RunSummary summary;
  std::vector<Instant> instants;
  int inexact_poses = 0;
};

RecordedRun RunCase(const AutoCase& c, std::uint64_t seed, LoadedController* package) {
  const sim::Task task = LoadTask(c);
  DataTap tap;
  AutoHook hook(task, seed, tap, package);
  sim::RunOptions o = Options(c, seed);
  o.control_hook = &hook;
  if (package != nullptr) package->Init();
  auto s = sim::RunTask(task, o, {&tap});
  EXPECT_TRUE(s.ok()) << s.error();
  return {s.ok() ? *s : sim::RunSummary{}, std::move(hook.instants), hook.inexact_poses};
}

// Bit for bit wherever the run made the package's designs; where it did not (a design made on a
// rounding-size moment arm's sign, FirstOtherDesign), bit for bit up to the first instant that
// uses the other design, and each case reproduced whole on one of its seeds at least.
// The force reference's deviation is relative to max(1 N, reference) (float_bounds.h).
struct Deviation : FloatDeviation {
  int inexact_poses = 0;
  double first_time = INFINITY;  // s, the first instant with a relative deviation above 1e-12
  // Float: the first instant at which a bundle's force reference is another whole count of
  // units, and the largest deviations before it; bundle outputs with another count.
  double first_flip = INFINITY, broadcast_before = 0, estimate_before = 0;
  int flipped = 0, outputs = 0;
};

// The first time (s) the run used a design other than the package's (its loop_designs against
// export.json's poses), or infinity when every design is the same. JointLoops::Design picks
// the bundle response it designs on by the sign of each moment arm at the limb's present pose;
// a bundle that does not cross a joint can have an arm of rounding size (1e-18 N m/N, either
// sign, e.g. the two-joint arm's elbow bundles about the shoulder), and the design then depends
// on where the limb is when the step comes. The package's is the design at rest (docs/export.md).
double FirstOtherDesign(const sim::RunSummary& s, const nlohmann::json& manifest,
                        const sim::Task& task) {
  double first = INFINITY;
  for (const nlohmann::json& d : s.loop_designs) {
    int j = 0;
    while (j < static_cast<int>(task.joints.size()) && task.joints[j].joint != d["joint"]) ++j;
    for (const nlohmann::json& p : manifest["poses"]) {
      if (p["reference_rad"][j].get<double>() != d["reference"].get<double>()) continue;
      const nlohmann::json& g = p["gains"][j];
      if (g["kp"] != d["kp"] || g["ki"] != d["ki"] || g["kd"] != d["kd"]) {
        first = std::min(first, p["first_time"].get<double>());
        std::printf("  the run designed %s at %.4f rad with kp %.6g, the package has kp %.6g\n",
                    d["joint"].get<std::string>().c_str(), d["reference"].get<double>(),
                    d["kp"].get<double>(), g["kp"].get<double>());
      }
    }
  }
  return first;
}

Deviation Replay(LoadedController& c, const std::vector<Instant>& log) {
  Deviation d;
  c.Init();
  std::vector<double> out;
  for (const Instant& k : log) {
    c.Step(k.in, out);
    bool exact = false;
    c.pose(&exact);
    d.inexact_poses += exact ? 0 : 1;
    for (int i = 0; i < c.bundles(); ++i) {
      const sim::ControlInstant& w = k.decided;
      const double want[5] = {w.force_reference[i], w.broadcast[i].p_on, w.broadcast[i].p_off,
                              w.estimated_on[i], w.estimated_on_variance[i]};
      const double* got = &out[5 * i];
      const double fr = std::abs(got[0] - want[0]) / std::max(1.0, want[0]);
      if (fr > kFloatForceRef) d.first_flip = std::min(d.first_flip, w.time);
      if (w.time < d.first_flip) {
        d.force_reference = std::max(d.force_reference, fr);
        d.broadcast_before =
            std::max({d.broadcast_before, std::abs(got[1] - want[1]), std::abs(got[2] - want[2])});
        d.estimate_before = std::max(d.estimate_before, std::abs(got[3] - want[3]));
      }
      ++d.outputs;
      d.flipped += fr > kFloatForceRef ? 1 : 0;
      d.AddOutput(got, want);
      for (int f = 0; f < 5; ++f) {
        if (Rel(got[f], want[f]) > 1e-12) d.first_time = std::min(d.first_time, w.time);
      }
    }
  }
  return d;
}

TEST(ExportAutoLoop, DoubleReproducesTheLoopsOnRecordedRuns) {
  for (const AutoCase& c : Cases()) {
    nlohmann::json manifest;
    auto ctl = Load(c, Precision::kDouble, "auto_double", &manifest);
    ASSERT_TRUE(ctl) << c.label;
    const sim::Task task = LoadTask(c);
    EXPECT_EQ(ctl->joints(), static_cast<int>(task.joints.size()));
    int whole = 0;
    for (std::uint64_t seed : {1, 7}) {
      const RecordedRun run = RunCase(c, seed, nullptr);
      ASSERT_GE(run.instants.size(), static_cast<size_t>(c.duration) - 1);
      const Deviation d = Replay(*ctl, run.instants);
      const double other = FirstOtherDesign(run.summary, manifest, task);
      std::printf(
          "%s seed %d: %zu instants, %d bundles, %d joints, largest relative deviation %.3g%s\n",
          c.label.c_str(), static_cast<int>(seed), run.instants.size(), ctl->bundles(),
          ctl->joints(), d.relative,
          std::isinf(other) ? "" : " (the run made another design: compared up to it)");
      // The run designs at the reference poses, as the package does: the same designs.
      EXPECT_TRUE(std::isinf(other))
          << c.label << " seed " << seed << ": another design at " << other;
      EXPECT_LE(d.relative, 1e-12) << c.label << " seed " << seed;
      whole += std::isinf(other) ? 1 : 0;
      // The schedule's references are the table's poses: never the nearest-pose fallback.
      EXPECT_EQ(d.inexact_poses, 0) << c.label;
    }
    EXPECT_GE(whole, 1) << c.label;
  }
}

TEST(ExportAutoLoop, FloatStaysWithinItsStatedBound) {
  FloatDeviation worst;
  for (const AutoCase& c : Cases()) {
    auto ctl = Load(c, Precision::kFloat, "auto_float");
    ASSERT_TRUE(ctl) << c.label;
    const RecordedRun run = RunCase(c, 1, nullptr);
    const Deviation d = Replay(*ctl, run.instants);
    std::printf(
        "%s float: first other count at %g s; before it broadcast %.3g, estimate %.3g, force "
        "reference %.3g; variance %.3g; %d of %d outputs with another count\n",
        c.label.c_str(), d.first_flip, d.broadcast_before, d.estimate_before, d.force_reference,
        d.variance, d.flipped, d.outputs);
    worst.Widen(d);
  }
  worst.ExpectWithinTheFloatBound();
}

// Every metric of the run summary (the tracked joint's, each joint's and each bundle's).
std::vector<std::pair<std::string, double>> Metrics(const sim::RunSummary& s) {
  std::vector<std::pair<std::string, double>> out;
  const nlohmann::json j = s.ToJson();
  for (auto it = j["metrics"].begin(); it != j["metrics"].end(); ++it) {
    out.push_back({it.key(), it.value().is_number() ? it.value().get<double>() : NAN});
  }
  for (const sim::JointSummary& js : s.joints) {
    out.push_back({js.joint + ".tracking_rmse", js.tracking_rmse});
    out.push_back({js.joint + ".max_overshoot", js.max_overshoot});
    out.push_back({js.joint + ".settled_fraction", js.settled_fraction});
  }
  for (const sim::BundleSummary& b : s.bundles) {
    out.push_back({b.actuator + ".estimator_rmse", b.estimator_rmse});
    out.push_back({b.actuator + ".peak_temperature", b.peak_temperature});
  }
  return out;
}

// Runs where the C++ loop made the package's designs (FirstOtherDesign) must give identical
// metrics: the first two such seeds of 1-10 per case (at least one).
TEST(ExportAutoLoop, DoubleDrivesThePlantToTheSameMetrics) {
  for (const AutoCase& c : Cases()) {
    nlohmann::json manifest;
    auto ctl = Load(c, Precision::kDouble, "auto_closed_double", &manifest);
    ASSERT_TRUE(ctl) << c.label;
    const sim::Task task = LoadTask(c);
    int compared = 0;
    for (std::uint64_t seed = 1; seed <= 2; ++seed) {
      const RecordedRun ref = RunCase(c, seed, nullptr);
      ASSERT_TRUE(std::isinf(FirstOtherDesign(ref.summary, manifest, task))) << c.label;
      const RecordedRun got = RunCase(c, seed, ctl.get());
      const auto a = Metrics(ref.summary), b = Metrics(got.summary);
      ASSERT_EQ(a.size(), b.size());
      ASSERT_GT(a.size(), 10u);
      for (size_t k = 0; k < a.size(); ++k) {
        EXPECT_TRUE(a[k].second == b[k].second ||
                    (std::isnan(a[k].second) && std::isnan(b[k].second)))
            << c.label << " seed " << seed << " " << a[k].first << ": " << a[k].second << " vs "
            << b[k].second;
      }
      std::printf(
          "%s closed loop (double), seed %d: every metric identical (tracking RMSE %.6g rad)\n",
          c.label.c_str(), static_cast<int>(seed), got.summary.metrics.tracking_rmse);
      ++compared;
    }
    EXPECT_EQ(compared, 2) << c.label;
  }
}

// The float package driving the plant, 20 seeds: each metric's mean within 5 % (relative; 0.02
// absolute near 0) of the C++ loop's, as for the hand-set tasks (docs/export.md), over the
// seeds (every run makes the package's designs: FirstOtherDesign).
TEST(ExportAutoLoop, FloatGivesTheSameMetricsOver20Seeds) {
  std::vector<AutoCase> cases = {Cases()[0], Cases()[2]};
  if (Cases().size() > 4) cases.push_back(Cases()[4]);
  for (const AutoCase& c : cases) {
    AutoCase shorter = c;
    shorter.duration = std::min(c.duration, 40.0);
    nlohmann::json manifest;
    auto ctl = Load(shorter, Precision::kFloat, "auto_closed_float", &manifest);
    ASSERT_TRUE(ctl) << c.label;
    const sim::Task task = LoadTask(c);
    MetricMeans means({"tracking_rmse", "iae", "overshoot", "settled_fraction", "switching_rate"});
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
      const RecordedRun ref = RunCase(shorter, seed, nullptr);
      ASSERT_TRUE(std::isinf(FirstOtherDesign(ref.summary, manifest, task))) << c.label;
      const RecordedRun got = RunCase(shorter, seed, ctl.get());
      means.Add(ref.summary.ToJson()["metrics"], got.summary.ToJson()["metrics"]);
    }
    ASSERT_EQ(means.runs(), 20) << c.label;
    std::printf("%s float: %d seeds compared, %d with the same tracking RMSE\n", c.label.c_str(),
                means.runs(), means.identical());
    means.ExpectTheSame(c.label);
  }
}

// The package's allocation and rounding against src/control/torque_allocation.cc on random
// problems of the two-joint arm's shape (six bundles; one or two joint rows and up to two
// stiffness rows; arms of both signs and sizes, floors at 5 % of capacity, prices >= 1):
// bit-identical tensions and whole-unit choices.
TEST(ExportAutoLoop, AllocationAndRoundingAreTheControllersBitForBit) {
  auto pkg = ExportController(LoadTask(Cases()[2]), Options(Cases()[2], 1), Precision::kDouble);
  ASSERT_TRUE(pkg.ok()) << pkg.error();
  const auto dir = FreshDir("alloc");
  testing::WriteFiles(pkg->files, dir);
  const std::string so = (dir / "liballoc.so").string();
  ASSERT_EQ(testing::Shell(std::string(RECRUIT_HOST_CC) + " " + testing::HostCFlags() +
                           " -Wno-unused-function -fPIC -shared -I" + dir.string() + " " + kSrc +
                           "/tests/export/alloc_shim.c -lm -o " + so),
            0);
  void* h = dlopen(so.c_str(), RTLD_NOW | RTLD_LOCAL);
  ASSERT_NE(h, nullptr) << dlerror();
  using Tensions = void (*)(int, const double*, const double*, const double*, const double*,
                            const double*, double*);
  using Round = void (*)(int, const double*, const double*, const double*, const double*,
                         const double*, const double*, const double*, double*);
  const auto nb_of = reinterpret_cast<int (*)()>(dlsym(h, "alloc_bundles"));
  const auto rows_of = reinterpret_cast<int (*)()>(dlsym(h, "alloc_max_rows"));
  const auto units_of = reinterpret_cast<int (*)(int)>(dlsym(h, "alloc_units"));
  const auto tensions = reinterpret_cast<Tensions>(dlsym(h, "alloc_tensions"));
  const auto round = reinterpret_cast<Round>(dlsym(h, "alloc_round"));
  ASSERT_TRUE(nb_of && rows_of && units_of && tensions && round);
  const int nb = nb_of();
  ASSERT_EQ(nb, 6);
  ASSERT_EQ(rows_of(), 4);
  Eigen::VectorXi units(nb);
  for (int b = 0; b < nb; ++b) units[b] = units_of(b);
  std::mt19937_64 gen(11);
  std::uniform_real_distribution<double> u(-1, 1);
  int differ = 0, rounded_differ = 0, n = 0, at_bound = 0;
  for (int rows = 1; rows <= 4; ++rows) {
    for (int trial = 0; trial < 5000; ++trial, ++n) {
      control::AllocationProblem p;
      p.arms.resize(rows, nb);
      p.torque.resize(rows);
      p.cap.resize(nb);
      p.floor.resize(nb);
      p.price.resize(nb);
      std::vector<double> arms(rows * nb);
      for (int j = 0; j < rows; ++j) {
        p.torque[j] = (j < 2 ? 3 : 0.3) * u(gen);  // N m, or a stiffness row's N m/rad
        for (int b = 0; b < nb; ++b) {
          // a bundle that does not cross a joint: a rounding-size arm, as on the two-joint arm
          p.arms(j, b) = b % 3 == 2 && j == 0 ? 1e-18 * u(gen) : (j < 2 ? 0.01 : 0.003) * u(gen);
          arms[j * nb + b] = p.arms(j, b);
        }
      }
      for (int b = 0; b < nb; ++b) {
        p.cap[b] = 50 + 250 * std::abs(u(gen));
        p.floor[b] = 0.05 * p.cap[b];
        p.price[b] = 1 + 2 * std::abs(u(gen));
      }
      const Eigen::VectorXd want = control::AllocateTensions(p);
      std::vector<double> got(nb);
      tensions(rows, arms.data(), p.torque.data(), p.floor.data(), p.cap.data(), p.price.data(),
               got.data());
      for (int b = 0; b < nb; ++b) {
        at_bound += want[b] == p.floor[b] || want[b] == p.cap[b];
        if (got[b] != want[b]) {
          ++differ;
          break;
        }
      }
      Eigen::VectorXd unit_force(nb);
      for (int b = 0; b < nb; ++b) unit_force[b] = p.cap[b] / units[b];
      const Eigen::VectorXd whole = control::RoundToUnits(p, want, unit_force, units);
      std::vector<double> got_whole(nb);
      round(rows, arms.data(), p.torque.data(), p.floor.data(), p.cap.data(), p.price.data(),
            want.data(), unit_force.data(), got_whole.data());
      for (int b = 0; b < nb; ++b) {
        if (got_whole[b] != whole[b]) {
          ++rounded_differ;
          break;
        }
      }
    }
  }
  dlclose(h);
  std::printf(
      "allocation: %d problems, %d bundle tensions at a bound; %d allocations and %d "
      "roundings differ from the C++ ones\n",
      n, at_bound, differ, rounded_differ);
  EXPECT_GT(at_bound, n);  // the box constraints are active, not only the free minimum
  EXPECT_EQ(differ, 0);
  EXPECT_EQ(rounded_differ, 0);
}

// A reference the schedule never reaches: the nearest pose's design, flagged.
TEST(ExportAutoLoop, AReferenceOffTheScheduleUsesTheNearestPose) {
  const AutoCase c = Cases()[2];
  auto ctl = Load(c, Precision::kDouble, "auto_offschedule");
  ASSERT_TRUE(ctl);
  const RecordedRun run = RunCase(c, 1, nullptr);
  std::vector<double> in = run.instants.back().in, out;
  ctl->Init();
  ctl->Step(in, out);
  bool exact = false;
  const int p = ctl->pose(&exact);
  EXPECT_TRUE(exact);
  in[0] += 0.01;  // the first joint 0.01 rad off its last reference
  ctl->Step(in, out);
  EXPECT_EQ(ctl->pose(&exact), p);
  EXPECT_FALSE(exact);
  for (double v : out) EXPECT_FALSE(std::isinf(v));
}

// ---------------------------------------------------------------------------------------------
// Cortex-M4F: a self-tuned task's float package cross-compiled (as export_test.cc's ExportM4
// test, tests/export/m4_build.h, docs/export.md), its flash and RAM, and a recorded run replayed
// under QEMU against the host build of the same source.

TEST(ExportAutoLoopM4, CrossCompilesAndReplaysUnderQemu) {
  if (!testing::HasM4Tools()) {
    GTEST_SKIP() << "arm-none-eabi-gcc or qemu-system-arm is not installed "
                    "(scripts/install-deps.sh installs them)";
  }
  for (const AutoCase& c : {Cases()[1], Cases()[2], Cases()[3]}) {
    auto pkg = ExportController(LoadTask(c), Options(c, 1), Precision::kFloat);
    ASSERT_TRUE(pkg.ok()) << pkg.error();
    const M4Package m4(FreshDir("m4_auto"));
    testing::WriteFiles(pkg->files, m4.dir());
    ASSERT_TRUE(m4.BuildForSize("recruit_controller.c", "recruit_controller.o"));
    const M4Package::Footprint f = m4.ReadFootprint({"ctl"});
    m4.ExpectNoHeapOrStdio();

    // A recorded run, replayed on the host and on the M4.
    const RecordedRun run = RunCase(c, 3, nullptr);
    {
      std::ofstream out(m4.dir() / "log.txt");
      out << run.instants.size() << " " << run.instants.front().decided.sensed_force.size() << "\n";
      for (const Instant& k : run.instants) {
        for (double v : k.in) out << testing::FloatHex(v) << " ";
        out << "\n";
      }
    }
    ASSERT_TRUE(m4.ReplayOnHostAndM4(120));
    const M4Package::Replayed host = m4.ReadReplay("host.txt");
    const M4Package::Replayed target = m4.ReadReplay("m4.txt");
    const size_t nb = run.instants.front().decided.sensed_force.size();
    ASSERT_EQ(host.rows.size(), run.instants.size() * nb);
    ASSERT_EQ(target.rows.size(), host.rows.size());
    ASSERT_EQ(target.steps, static_cast<int>(run.instants.size()));
    size_t same = 0;
    for (size_t r = 0; r < host.rows.size(); ++r) same += host.rows[r] == target.rows[r] ? 1 : 0;
    // No sinf in these packages: IEEE arithmetic and libm's sqrt, floor, ceil on both sides.
    EXPECT_EQ(same, host.rows.size()) << c.label << ": the M4 and the host build differ";
    std::printf(
        "m4 %s: recruit_controller.o text %lu, program flash %lu (text %lu, data %lu), context "
        "%lu, stack frames %lu, RAM %lu; %zu outputs bit-identical to the host build of %zu; "
        "about %.0f instructions per control step (%lu ticks over %d steps)\n",
        c.label.c_str(), f.object_text, f.text + f.data, f.text, f.data, f.context, f.stack,
        f.context + f.stack, same, host.rows.size(), 40.0 * target.ticks / target.steps,
        target.ticks, target.steps);
    EXPECT_GT(target.ticks, 0u);
  }
}

}  // namespace file_auto_loop_test
}  // namespace recruit::exporter
