// The exported C controller against the C++ controller it was generated from: fed the control
// instants recorded from RunTask it gives the same broadcasts and estimates (double: to 1e-12
// relative; float: within the bound docs/export.md states), and driving the simulated plant in
// its place (RunTask's ControlInstantHook) it gives the same metrics.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "export/controller_export.h"
#include "sim/run_task.h"
#include "sim/task.h"
#include "tests/export/package_loader.h"

namespace recruit::exporter {
namespace {

using testing::FreshDir;
using testing::LoadedController;

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

sim::Task LoadTask(const std::string& name) {
  auto t = sim::Task::FromFile(std::string(RECRUIT_SOURCE_DIR) + "/models/tasks/" + name);
  EXPECT_TRUE(t.ok()) << t.error();
  return *t;
}

struct Case {
  std::string task;
  std::string estimator;  // "" = the task's
  double duration;
};

sim::RunOptions Options(const Case& c, std::uint64_t seed) {
  sim::RunOptions o;
  if (!c.estimator.empty()) o.estimator = c.estimator;
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

// Largest deviations of the replayed outputs from the recorded ones: broadcasts (absolute),
// estimates (units), variances (relative to max(1, |var|)), force references (N), and the
// largest of all relative to max(|a|, |b|) (the double criterion).
struct Deviation {
  double broadcast = 0, estimate = 0, variance = 0, force_reference = 0, relative = 0;
};

double Rel(double a, double b) {
  if (std::isnan(a) && std::isnan(b)) return 0;
  const double scale = std::max(std::abs(a), std::abs(b));
  return scale == 0 ? 0 : std::abs(a - b) / scale;
}

Deviation Replay(LoadedController& c, const std::vector<sim::ControlInstant>& log) {
  Deviation d;
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
      d.broadcast = std::max({d.broadcast, std::abs(got[1] - want[1]), std::abs(got[2] - want[2])});
      d.estimate = std::max(d.estimate, std::abs(got[3] - want[3]));
      if (!(std::isnan(want[4]) && std::isnan(got[4]))) {
        d.variance =
            std::max(d.variance, std::abs(got[4] - want[4]) / std::max(1.0, std::abs(want[4])));
      }
      for (int f = 0; f < 5; ++f) d.relative = std::max(d.relative, Rel(got[f], want[f]));
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

const std::vector<Case>& Cases() {
  static const std::vector<Case> cases = {{"isometric_steps.json", "", 60},
                                          {"arm_reach_hold.json", "", 60},
                                          {"arm_push.json", "", 40},
                                          {"arm_reach_hold.json", "output", 40},
                                          {"arm_reach_hold.json", "kalman2", 40}};
  return cases;
}

// The float package's bound against the C++ controller (double) over the recorded runs of
// Cases(), documented in docs/export.md: measured maxima there, with a margin.
constexpr double kFloatBroadcast = 2e-4;  // p_on, p_off (absolute)
constexpr double kFloatEstimate = 2e-3;   // units
constexpr double kFloatVariance = 1e-3;   // relative to max(1, variance)
constexpr double kFloatForceRef = 1e-4;   // N

TEST(ExportEquivalence, DoubleReproducesTheControllerOnRecordedRuns) {
  for (const Case& c : Cases()) {
    auto ctl = Load(c, Precision::kDouble, "double_" + c.task + c.estimator);
    ASSERT_TRUE(ctl);
    for (std::uint64_t seed : {1, 7}) {
      const auto log = Record(c, seed);
      ASSERT_GT(log.size(), 30u);
      const Deviation d = Replay(*ctl, log);
      std::printf("%s %s seed %d: %zu instants, largest relative deviation %.3g\n", c.task.c_str(),
                  c.estimator.c_str(), static_cast<int>(seed), log.size(), d.relative);
      EXPECT_LE(d.relative, 1e-12) << c.task << " " << c.estimator << " seed " << seed;
    }
  }
}

TEST(ExportEquivalence, FloatStaysWithinItsStatedBound) {
  Deviation worst;
  for (const Case& c : Cases()) {
    auto ctl = Load(c, Precision::kFloat, "float_" + c.task + c.estimator);
    ASSERT_TRUE(ctl);
    for (std::uint64_t seed : {1, 7}) {
      const Deviation d = Replay(*ctl, Record(c, seed));
      std::printf(
          "%s %s seed %d: broadcast %.3g, estimate %.3g units, variance %.3g, force "
          "reference %.3g N\n",
          c.task.c_str(), c.estimator.c_str(), static_cast<int>(seed), d.broadcast, d.estimate,
          d.variance, d.force_reference);
      worst.broadcast = std::max(worst.broadcast, d.broadcast);
      worst.estimate = std::max(worst.estimate, d.estimate);
      worst.variance = std::max(worst.variance, d.variance);
      worst.force_reference = std::max(worst.force_reference, d.force_reference);
    }
  }
  EXPECT_LE(worst.broadcast, kFloatBroadcast);
  EXPECT_LE(worst.estimate, kFloatEstimate);
  EXPECT_LE(worst.variance, kFloatVariance);
  EXPECT_LE(worst.force_reference, kFloatForceRef);
  // Not trivially zero: float differs from double somewhere.
  EXPECT_GT(worst.estimate, 0.0);
}

Result<sim::RunSummary> RunWith(const Case& c, std::uint64_t seed, sim::ControlInstantHook* h) {
  sim::RunOptions o = Options(c, seed);
  o.control_hook = h;
  return sim::RunTask(LoadTask(c.task), o);
}

TEST(ExportClosedLoop, DoubleDrivesThePlantToTheSameMetrics) {
  for (const Case& c : {Cases()[0], Cases()[1]}) {
    auto ctl = Load(c, Precision::kDouble, "closed_double_" + c.task);
    ASSERT_TRUE(ctl);
    for (std::uint64_t seed : {1, 2}) {
      auto ref = RunWith(c, seed, nullptr);
      ctl->Init();
      ExportedDriver driver(*ctl);
      auto got = RunWith(c, seed, &driver);
      ASSERT_TRUE(ref.ok() && got.ok());
      const nlohmann::json a = ref->ToJson()["metrics"], b = got->ToJson()["metrics"];
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

}  // namespace
}  // namespace recruit::exporter
