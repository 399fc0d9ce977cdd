// The exported C controller against the C++ controller it was generated from: fed the control
// instants recorded from RunTask it gives the same broadcasts and estimates (double: to 1e-12
// relative; float: within the bound docs/export.md states), and driving the simulated plant in
// its place (RunTask's ControlInstantHook) it gives the same metrics. Tasks: the bench's and the
// elbow arm's with hand-set gains; the self-tuned loop's package: auto_loop_test.cc.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "export/controller_export.h"
#include "sim/run_task.h"
#include "sim/task.h"
#include "tests/export/float_bounds.h"
#include "tests/export/m4_build.h"
#include "tests/export/package_loader.h"

namespace recruit::exporter {
namespace file_export_test {

using testing::FloatDeviation;
using testing::FreshDir;
using testing::kFloatBroadcast;
using testing::kFloatEstimate;
using testing::kFloatForceRef;
using testing::kFloatVariance;
using testing::LoadedController;
using testing::M4Package;
using testing::MetricMeans;
using testing::Rel;

// Records what the task's own controllers saw and decided at every control instant.
class Recorder : public sim::ControlInstantHook {
 public:
  bool Replaces() const override { return false; }
  Status OnInstant(sim::ControlInstant& c) override {
    instants.push_back(c);
    return Status::Ok();
  }
  std::vector<sim::ControlInstant> instants;
};

// The exported controller in place of the task's own.
class ExportedDriver : public sim::ControlInstantHook {
 public:
  explicit ExportedDriver(LoadedController& c) : c_(c) {}
  bool Replaces() const override { return true; }
  Status OnInstant(sim::ControlInstant& c) override {
    const int nb = c_.bundles();
    std::vector<double> in{c.reference, c.angle, c.angular_velocity}, out;
    for (int i = 0; i < nb; ++i) in.push_back(c.sensed_force[i]);
    for (int i = 0; i < nb; ++i) in.push_back(c.tendon_length[i]);
    c_.Step(in, out);
    for (int i = 0; i < nb; ++i) {
      c.force_reference[i] = out[5 * i];
      c.broadcast[i] = {out[5 * i + 1], out[5 * i + 2]};
      c.estimated_on[i] = out[5 * i + 3];
      c.estimated_on_variance[i] = out[5 * i + 4];
    }
    return Status::Ok();
  }

 private:
  LoadedController& c_;
};

// `path`: relative to the source tree. The shipped arm tasks run the self-tuned loop
// (auto_loop_test.cc); the hand-set form's package is tested here on tests/export/data's copies
// of them with hand-set gains.
sim::Task LoadTask(const std::string& path) {
  auto t = sim::Task::FromFile(std::string(RECRUIT_SOURCE_DIR) + "/" + path);
  EXPECT_TRUE(t.ok()) << t.error();
  return *t;
}

const std::string kSteps = "models/tasks/isometric_steps.json";
const std::string kArmHand = "tests/export/data/arm_reach_hold_hand.json";
const std::string kPushHand = "tests/export/data/arm_push_hand.json";
const std::string kLiftHand = "tests/export/data/arm_lift_hand.json";

struct Case {
  std::string task;       // relative to the source tree
  std::string estimator;  // "" = the task's
  double duration;
  std::string filter_model = "";  // "" = the task's
};

sim::RunOptions Options(const Case& c, std::uint64_t seed) {
  sim::RunOptions o;
  if (!c.estimator.empty()) o.estimator = c.estimator;
  if (!c.filter_model.empty()) o.filter_model = c.filter_model;
  o.duration = c.duration;
  o.seed = seed;
  o.quiet = true;
  return o;
}

// The package for a case, compiled and loaded.
std::unique_ptr<LoadedController> Load(const Case& c, Precision p, const std::string& dir_name) {
  const sim::Task task = LoadTask(c.task);
  auto pkg = ExportController(task, Options(c, 1), p);
  EXPECT_TRUE(pkg.ok()) << pkg.error();
  if (!pkg.ok()) return nullptr;
  const auto dir = FreshDir(dir_name);
  testing::WriteFiles(pkg->files, dir);
  auto loaded = std::make_unique<LoadedController>(dir);
  EXPECT_EQ(loaded->error(), "");
  return loaded->error().empty() ? std::move(loaded) : nullptr;
}

// The replayed outputs' deviations from the recorded ones (force references in N).
FloatDeviation Replay(LoadedController& c, const std::vector<sim::ControlInstant>& log) {
  FloatDeviation d;
  c.Init();
  const int nb = c.bundles();
  std::vector<double> out;
  for (const sim::ControlInstant& k : log) {
    std::vector<double> in{k.reference, k.angle, k.angular_velocity};
    for (int i = 0; i < nb; ++i) in.push_back(k.sensed_force[i]);
    for (int i = 0; i < nb; ++i) in.push_back(k.tendon_length[i]);
    c.Step(in, out);
    for (int i = 0; i < nb; ++i) {
      const double want[5] = {k.force_reference[i], k.broadcast[i].p_on, k.broadcast[i].p_off,
                              k.estimated_on[i], k.estimated_on_variance[i]};
      const double* got = &out[5 * i];
      d.force_reference = std::max(d.force_reference, std::abs(got[0] - want[0]));
      d.AddOutput(got, want);
    }
  }
  return d;
}

std::vector<sim::ControlInstant> Record(const Case& c, std::uint64_t seed) {
  Recorder rec;
  sim::RunOptions o = Options(c, seed);
  o.control_hook = &rec;
  auto run = sim::RunTask(LoadTask(c.task), o);
  EXPECT_TRUE(run.ok()) << run.error();
  return rec.instants;
}

// The bench's identified model with an uncertain initial belief (P0 = diag(0.5, ..., 0.5) on
// x0 = N in state 0, projected by the filter onto 1^T P = 0): the identified models start
// certain (P0 = 0), so this exercises the initial projection.
std::string UncertainStartModel() {
  static const std::string path = [] {
    const std::string src =
        std::string(RECRUIT_SOURCE_DIR) + "/models/identified/bundle_903e47abb54d0604_dt1_m20.json";
    std::ifstream in(src);
    nlohmann::json j = nlohmann::json::parse(in);
    auto& P0 = j["initial"]["P0"];
    for (size_t i = 0; i < P0.size(); ++i) P0[i][i] = 0.5;
    const auto out = FreshDir("models") / "bench_p0.json";
    std::ofstream(out) << j.dump();
    return out.string();
  }();
  return path;
}

// The same with measurement noise growing with the units in transit (R_transit = 0.01 N^2 per
// unit in transit and R_transit2 = 0.001 N^2 per squared unit, against R = 0.0027 N^2): the
// package evaluates R at the predicted counts.
std::string TransitNoiseModel() {
  static const std::string path = [] {
    std::ifstream in(UncertainStartModel());
    nlohmann::json j = nlohmann::json::parse(in);
    j["R_transit"] = {{0.01}};
    j["R_transit2"] = {{0.001}};
    const auto out = FreshDir("models_transit") / "bench_p0_transit.json";
    std::ofstream(out) << j.dump();
    return out.string();
  }();
  return path;
}

// The elbow arm's shipped flexor and extensor models (dT = 1 s) with R_transit = their R,
// R_transit2 = R / 10 and an
// uncertain start (as UncertainStartModel): the length-aware filter with the transit term, as
// "{bundle}" files (one per bundle).
std::string ArmTransitModels() {
  static const std::string path = [] {
    const auto dir = FreshDir("models_arm_transit");
    const std::string shipped = std::string(RECRUIT_SOURCE_DIR) + "/models/identified/";
    for (const auto& [bundle, file] :
         {std::pair<std::string, std::string>{"flexor", "flexor_104229eb693169de_dt1_m20.json"},
          {"extensor", "extensor_748ab7310148dd2a_dt1_m20.json"}}) {
      std::ifstream in(shipped + file);
      nlohmann::json j = nlohmann::json::parse(in);
      j["R_transit"] = j["R"];
      j["R_transit2"] = {{j["R"][0][0].get<double>() / 10}};
      auto& P0 = j["initial"]["P0"];
      for (size_t i = 0; i < P0.size(); ++i) P0[i][i] = 0.5;
      std::ofstream(dir / (bundle + ".json")) << j.dump();
    }
    return (dir / "{bundle}.json").string();
  }();
  return path;
}

const std::vector<Case>& Cases() {
  static const std::vector<Case> cases = {{kSteps, "", 40, UncertainStartModel()},
                                          {kSteps, "", 40, TransitNoiseModel()},
                                          {kArmHand, "", 60, ArmTransitModels()},
                                          {kSteps, "", 60},
                                          {kArmHand, "", 60},
                                          {kPushHand, "", 40},
                                          {kLiftHand, "", 40},  // the payload changes at 20 s
                                          {kArmHand, "output", 40},
                                          {kArmHand, "kalman2", 40}};
  return cases;
}

TEST(ExportEquivalence, DoubleReproducesTheControllerOnRecordedRuns) {
  for (size_t n = 0; n < Cases().size(); ++n) {
    const Case& c = Cases()[n];
    auto ctl = Load(c, Precision::kDouble, "double_" + std::to_string(n));
    ASSERT_TRUE(ctl);
    for (std::uint64_t seed : {1, 7}) {
      const auto log = Record(c, seed);
      ASSERT_GT(log.size(), 30u);
      // The uncertain start shows in the first estimate's variance (certain: 0).
      if (!c.filter_model.empty()) {
        EXPECT_GT(log.front().estimated_on_variance[0], 0.1);
      }
      const FloatDeviation d = Replay(*ctl, log);
      std::printf("%s %s%s seed %d: %zu instants, largest relative deviation %.3g\n",
                  c.task.c_str(), c.estimator.c_str(), c.filter_model.empty() ? "" : " (P0 > 0)",
                  static_cast<int>(seed), log.size(), d.relative);
      EXPECT_LE(d.relative, 1e-12) << c.task << " " << c.estimator << " seed " << seed;
    }
  }
}

// The transit case's package carries R_transit and its states (Cases()' second case, replayed
// above), and the term changes what the controller does: not a case equal to the first.
TEST(ExportEquivalence, TransitNoiseReachesThePackage) {
  const Case plain = Cases()[0], transit = Cases()[1];
  auto pkg = ExportController(LoadTask(transit.task), Options(transit, 1), Precision::kDouble);
  ASSERT_TRUE(pkg.ok()) << pkg.error();
  std::string c_file;
  for (const ExportedFile& f : pkg->files) {
    if (f.name == "recruit_controller.c") c_file = f.contents;
  }
  EXPECT_NE(c_file.find(".R_transit = 0.01"), std::string::npos);
  EXPECT_NE(c_file.find(".R_transit2 = 0.001"), std::string::npos);
  // Each state's transit weight, from the model file here: its force step to the state its
  // units most likely move on to (interior column), over the force range; cold and hot 0.
  std::ifstream in(TransitNoiseModel());
  const nlohmann::json j = nlohmann::json::parse(in);
  const auto h = j["H"][0].get<std::vector<double>>();
  const auto interior = j["transition"]["interior"].get<std::vector<std::vector<double>>>();
  const double range =
      *std::max_element(h.begin(), h.end()) - *std::min_element(h.begin(), h.end());
  const size_t head = c_file.find("b0_transit[20] = {");
  ASSERT_NE(head, std::string::npos);
  std::istringstream values(c_file.substr(c_file.find('{', head) + 1));
  for (size_t col = 0; col < h.size(); ++col) {
    size_t next = col;
    for (size_t row = 0; row < h.size(); ++row) {
      if (row != col && interior[row][col] > 0 &&
          (next == col || interior[row][col] > interior[next][col])) {
        next = row;
      }
    }
    const double expected =
        interior[col][col] < 1 && next != col ? std::abs(h[next] - h[col]) / range : 0.0;
    double written = -1;
    char comma = 0;
    values >> written >> comma;
    EXPECT_NEAR(written, expected, 1e-15) << "state " << col;
  }
  const auto a = Record(plain, 7), b = Record(transit, 7);
  ASSERT_EQ(a.size(), b.size());
  double largest = 0;
  for (size_t k = 0; k < a.size(); ++k) {
    largest =
        std::max(largest, std::abs(a[k].estimated_on_variance[0] - b[k].estimated_on_variance[0]));
  }
  EXPECT_GT(largest, 1e-3);
}

TEST(ExportEquivalence, FloatStaysWithinItsStatedBound) {
  FloatDeviation worst;
  for (size_t n = 0; n < Cases().size(); ++n) {
    const Case& c = Cases()[n];
    auto ctl = Load(c, Precision::kFloat, "float_" + std::to_string(n));
    ASSERT_TRUE(ctl);
    for (std::uint64_t seed : {1, 7}) {
      const FloatDeviation d = Replay(*ctl, Record(c, seed));
      std::printf(
          "%s %s seed %d: broadcast %.3g, estimate %.3g units, variance %.3g, force "
          "reference %.3g N\n",
          c.task.c_str(), c.estimator.c_str(), static_cast<int>(seed), d.broadcast, d.estimate,
          d.variance, d.force_reference);
      worst.Widen(d);
    }
  }
  worst.ExpectWithinTheFloatBound();
  // Not trivially zero: float differs from double somewhere.
  EXPECT_GT(worst.estimate, 0.0);
}

// Lost samples: a NaN force (the filter predicts only) and a NaN length (the model's reference
// length), fed to the C++ controllers RunTask would build (sim::TaskControllers) and to the
// package alike, on a force task's recorded instants.
TEST(ExportEquivalence, DoubleHandlesLostSamplesAsTheController) {
  for (const std::string estimator : {"kalman-augmented", "output"}) {
    const Case c{kSteps, estimator, 60};
    auto log = Record(c, 5);
    ASSERT_GT(log.size(), 30u);
    for (size_t k = 0; k < log.size(); ++k) {
      if (k % 7 == 3) log[k].sensed_force[0] = NAN;
      if (k % 11 == 5) log[k].tendon_length[0] = NAN;
    }
    auto cpp = sim::TaskControllers(LoadTask(c.task), Options(c, 5));
    ASSERT_TRUE(cpp.ok()) << cpp.error();
    ASSERT_EQ(cpp->size(), 1u);
    control::RecruitmentController& ctl = (*cpp)[0].controller;
    auto pkg = Load(c, Precision::kDouble, "lost_" + estimator);
    ASSERT_TRUE(pkg);
    std::vector<double> out;
    for (const sim::ControlInstant& k : log) {
      const control::Broadcast b = ctl.Step(k.reference, k.sensed_force[0], k.tendon_length[0]);
      pkg->Step({k.reference, 0, 0, k.sensed_force[0], k.tendon_length[0]}, out);
      EXPECT_EQ(out[0], k.reference);
      EXPECT_LE(Rel(out[1], b.p_on), 1e-12) << estimator << " t = " << k.time;
      EXPECT_LE(Rel(out[2], b.p_off), 1e-12) << estimator << " t = " << k.time;
      EXPECT_LE(Rel(out[3], ctl.estimated_on()), 1e-12) << estimator << " t = " << k.time;
      EXPECT_LE(Rel(out[4], ctl.estimated_on_variance()), 1e-12) << estimator << " t = " << k.time;
    }
  }
}

Result<sim::RunSummary> RunWith(const Case& c, std::uint64_t seed, sim::ControlInstantHook* h) {
  sim::RunOptions o = Options(c, seed);
  o.control_hook = h;
  return sim::RunTask(LoadTask(c.task), o);
}

// The run summaries' "metrics" of one seed with the C++ controller and driven by the package.
struct BothMetrics {
  bool ok = false;
  nlohmann::json cpp, package;
};
BothMetrics RunBoth(const Case& c, std::uint64_t seed, LoadedController& ctl) {
  auto ref = RunWith(c, seed, nullptr);
  ctl.Init();
  ExportedDriver driver(ctl);
  auto got = RunWith(c, seed, &driver);
  if (!ref.ok() || !got.ok()) return {};
  return {true, ref->ToJson()["metrics"], got->ToJson()["metrics"]};
}

TEST(ExportClosedLoop, DoubleDrivesThePlantToTheSameMetrics) {
  for (const Case& c : {Cases()[0], Cases()[1], Cases()[2]}) {
    auto ctl = Load(c, Precision::kDouble,
                    "closed_double_" + std::filesystem::path(c.task).stem().string());
    ASSERT_TRUE(ctl);
    for (std::uint64_t seed : {1, 2}) {
      const BothMetrics m = RunBoth(c, seed, *ctl);
      ASSERT_TRUE(m.ok);
      const nlohmann::json &a = m.cpp, &b = m.package;
      for (auto it = a.begin(); it != a.end(); ++it) {
        const double x = it.value().is_number() ? it.value().get<double>() : NAN;
        const double y = b[it.key()].is_number() ? b[it.key()].get<double>() : NAN;
        EXPECT_LE(Rel(x, y), 1e-12)
            << c.task << " seed " << seed << " " << it.key() << ": " << x << " vs " << y;
      }
      EXPECT_EQ(a["tracking_rmse"], b["tracking_rmse"]) << c.task << " seed " << seed;
      EXPECT_EQ(a["switching_rate"], b["switching_rate"]) << c.task << " seed " << seed;
    }
  }
}

// The float package driving the plant: over 20 seeds each metric's mean is that of the C++
// controller within kClosedLoopFloat (float_bounds.h). A broadcast 1e-7 off changes a unit's
// draw only rarely, so most runs are identical; one changed draw makes the rest of that run
// another sample of the same process.
TEST(ExportClosedLoop, FloatGivesTheSameMetricsOver20Seeds) {
  for (const Case& c : {Case{kSteps, "", 60}, Case{kArmHand, "", 40}}) {
    auto ctl =
        Load(c, Precision::kFloat, "closed_float_" + std::filesystem::path(c.task).stem().string());
    ASSERT_TRUE(ctl);
    MetricMeans means({"tracking_rmse", "iae", "overshoot", "settled_fraction", "switching_rate",
                       "estimator_rmse"});
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
      const BothMetrics m = RunBoth(c, seed, *ctl);
      ASSERT_TRUE(m.ok);
      means.Add(m.cpp, m.package);
    }
    std::printf("%s: %d of 20 seeds with the same tracking RMSE\n", c.task.c_str(),
                means.identical());
    means.ExpectTheSame(c.task);
  }
}

// ---------------------------------------------------------------------------------------------
// Cortex-M4F: the float package cross-compiled, its flash and RAM, and a recorded log replayed on
// QEMU against the host build (tests/export/m4_build.h).

float BitsFloat(unsigned long b) {
  const std::uint32_t u = static_cast<std::uint32_t>(b);
  float f;
  std::memcpy(&f, &u, sizeof f);
  return f;
}

// A replay row's five outputs ("k i" and their float bit patterns).
std::array<float, 5> RowFloats(const std::string& row) {
  int k, i;
  unsigned long v[5] = {0, 0, 0, 0, 0};
  EXPECT_EQ(std::sscanf(row.c_str(), "%d %d %lx %lx %lx %lx %lx", &k, &i, &v[0], &v[1], &v[2],
                        &v[3], &v[4]),
            7)
      << row;
  return {BitsFloat(v[0]), BitsFloat(v[1]), BitsFloat(v[2]), BitsFloat(v[3]), BitsFloat(v[4])};
}

// Records the case's run (seed 3, 110 instants, two bundles), replays it as float bit patterns
// through the package in m4.dir() on the host and on the M4 (qemu), and checks every output
// within the float bounds.
struct M4Replay {
  int identical = -1;  // of the 220 outputs, bit-identical to the host build's (-1: failed)
  unsigned long ticks = 0;
  int steps = 0;
};
M4Replay ReplayOnM4(const Case& c, const M4Package& m4) {
  // A recorded run as float bit patterns, replayed on the host and on the M4.
  const auto log = Record(c, 3);
  EXPECT_EQ(log.size(), 110u);
  {
    std::ofstream out(m4.dir() / "log.txt");
    out << log.size() << " 2\n";
    for (const sim::ControlInstant& k : log) {
      for (double x : {k.reference, k.angle, k.angular_velocity, k.sensed_force[0],
                       k.sensed_force[1], k.tendon_length[0], k.tendon_length[1]}) {
        out << testing::FloatHex(x) << " ";
      }
      out << "\n";
    }
  }
  if (log.size() != 110u || !m4.ReplayOnHostAndM4(60)) return {};
  const M4Package::Replayed host = m4.ReadReplay("host.txt");
  const M4Package::Replayed target = m4.ReadReplay("m4.txt");
  EXPECT_EQ(host.rows.size(), 220u);
  if (host.rows.size() != 220u || target.rows.size() != host.rows.size()) return {};
  int identical = 0;
  for (size_t r = 0; r < host.rows.size(); ++r) {
    const std::array<float, 5> a = RowFloats(host.rows[r]), b = RowFloats(target.rows[r]);
    identical += std::memcmp(a.data(), b.data(), sizeof(float) * 5) == 0 ? 1 : 0;
    EXPECT_LE(std::abs(a[0] - b[0]), kFloatForceRef) << "row " << r;
    EXPECT_LE(std::abs(a[1] - b[1]), kFloatBroadcast) << "row " << r;
    EXPECT_LE(std::abs(a[2] - b[2]), kFloatBroadcast) << "row " << r;
    EXPECT_LE(std::abs(a[3] - b[3]), kFloatEstimate) << "row " << r;
    EXPECT_LE(std::abs(a[4] - b[4]) / std::max(1.0f, std::abs(a[4])), kFloatVariance)
        << "row " << r;
  }
  EXPECT_EQ(target.steps, 110);
  return {identical, target.ticks, target.steps};
}

TEST(ExportM4, CrossCompilesWithinBudgetAndReplaysUnderQemu) {
  if (!testing::HasM4Tools()) {
    GTEST_SKIP() << "arm-none-eabi-gcc or qemu-system-arm is not installed "
                    "(scripts/install-deps.sh installs them)";
  }
  const Case c{kArmHand, "", 110};
  const sim::Task task = LoadTask(c.task);
  auto pkg = ExportController(task, Options(c, 1), Precision::kFloat);
  ASSERT_TRUE(pkg.ok()) << pkg.error();
  const M4Package m4(FreshDir("m4"));
  testing::WriteFiles(pkg->files, m4.dir());

  // Flash and RAM: the package with the smallest caller (no stdio), libm's sinf included.
  ASSERT_TRUE(m4.BuildForSize("recruit_controller.c recruit_unit.c",
                              "recruit_controller.o recruit_unit.o"));
  std::printf("%s", testing::ReadText(m4.dir() / "size.txt").c_str());
  // The controller's RAM: its context and in/out structs (size_main.c's statics) and its stack
  // frames.
  const M4Package::Footprint f = m4.ReadFootprint({"ctl", "in", "out"});
  const unsigned long flash = f.text + f.data, ram = f.context + f.stack;
  std::printf(
      "m4: flash %lu bytes (text %lu, data %lu; program bss %lu), RAM %lu bytes (context "
      "and i/o %lu, stack frames %lu)\n",
      flash, f.text, f.data, f.bss, ram, f.context, f.stack);
  EXPECT_LE(flash, 16u * 1024) << "the float package for m = 20, two bundles: <= 16 KB flash";
  EXPECT_LE(ram, 4u * 1024) << "<= 4 KB RAM";
  EXPECT_GT(f.context, 2u * 20 * 21 / 2 * 4) << "two packed 20 x 20 covariances at least";
  m4.ExpectNoHeapOrStdio();

  // Both packages together, as firmware wires them (tests/export/m4/firmware.c): it runs.
  const std::string src = M4Package::Sources();
  ASSERT_TRUE(m4.Sh(M4Package::Cc() + " -I. -nostdlib -T " + src + "m4.ld -Wl,--gc-sections " +
                    src + "startup.c " + src +
                    "firmware.c recruit_controller.c recruit_unit.c -lm -lc -lgcc -o "
                    "firmware.elf && timeout 60 qemu-system-arm -M mps2-an386 -nographic "
                    "-no-reboot -semihosting-config enable=on,target=native -kernel firmware.elf"));

  const M4Replay target = ReplayOnM4(c, m4);
  ASSERT_GE(target.identical, 0);
  ASSERT_EQ(target.steps, 110);
  std::printf(
      "m4: %d of 220 outputs bit-identical to the host build; %lu SysTick ticks over %d "
      "steps: about %.0f instructions per control step (40 per tick, -icount shift=0)\n",
      target.identical, target.ticks, target.steps, 40.0 * target.ticks / target.steps);
  EXPECT_GT(target.ticks, 0u);
}

// The same replay with the transit term: the arm's models with R_transit (ArmTransitModels).
TEST(ExportM4, TransitNoiseReplaysUnderQemuAsOnTheHost) {
  if (!testing::HasM4Tools()) {
    GTEST_SKIP() << "arm-none-eabi-gcc or qemu-system-arm is not installed "
                    "(scripts/install-deps.sh installs them)";
  }
  const Case c{kArmHand, "", 110, ArmTransitModels()};
  auto pkg = ExportController(LoadTask(c.task), Options(c, 1), Precision::kFloat);
  ASSERT_TRUE(pkg.ok()) << pkg.error();
  const M4Package m4(FreshDir("m4_transit"));
  testing::WriteFiles(pkg->files, m4.dir());
  const M4Replay target = ReplayOnM4(c, m4);
  std::printf("m4 (transit noise): %d of 220 outputs bit-identical to the host build\n",
              target.identical);
  EXPECT_GE(target.identical, 0);
}

}  // namespace file_export_test
}  // namespace recruit::exporter

namespace recruit::exporter {
namespace file_export_test {

// The C controller has no census: a task that asks for one is refused, naming the key, rather
// than exported without it.
TEST(ExportRefuses, ATaskWithACensus) {
  sim::Task task = LoadTask("tests/sim/data/census_loss.json");
  ASSERT_GT(task.controller.census_period, 0);
  auto pkg = ExportController(task, sim::RunOptions{}, Precision::kDouble);
  ASSERT_FALSE(pkg.ok());
  EXPECT_NE(pkg.error().find("controller.census_period: 2.5"), std::string::npos) << pkg.error();
  task.controller.census_period = 0;
  task.controller.estimator = "kalman-augmented";
  EXPECT_TRUE(ExportController(task, sim::RunOptions{}, Precision::kDouble).ok());
}

}  // namespace file_export_test
}  // namespace recruit::exporter
