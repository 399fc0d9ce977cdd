// recruit.sma as a stock MuJoCo program sees it. This program does not link librecruit_sma.so:
// it loads it with mj_loadPluginLibrary, compiles bundle models with MuJoCo's own loader and
// drives them only through ctrl, mj_step and MuJoCo's data API. References come from the
// MuJoCo-free SmaBundle driven directly (a different path from the same physics), from the
// binomial distribution, and from the run itself (copies, resets, threads must be bit-exact).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "common/rng.h"
#include "plugin/bundle.h"
#include "plugin/bundle_config.h"
#include "tests/plugin/mujoco_util.h"

namespace recruit::sma {
namespace file_engine_plugin_test {

using ::testing::AllOf;
using testing::Bench;
using testing::BenchXml;
using testing::ConfigXml;
using testing::DataPtr;
using ::testing::HasSubstr;
using testing::Load;
using testing::ModelPtr;
using testing::PluginState;
using testing::SameBits;

constexpr int kSlots = 2;  // per actuator before the bundle's block (plugin/README.md)
// SmaBundle header: magic, 8 RNG halves, cohorts, counter, pending, kept tension (3), reserved
constexpr int kHeader = 16;
constexpr int kRngHalves = 8;

ModelPtr MustLoad(const std::string& xml) {
  auto m = Load(xml);
  EXPECT_TRUE(m.ok()) << m.error();
  return m.ok() ? std::move(m).value() : nullptr;
}

// The bundle block of actuator k (in actuator order) of instance `inst`, by the documented
// layout: [next broadcast, reserved] then the block, actuator after actuator.
const double* Block(const mjModel* m, const mjData* d, int inst, int k, int block_size) {
  return d->plugin_state + m->plugin_stateadr[inst] + k * (kSlots + block_size) + kSlots;
}

// The plugin sensor's values: count, tension, mean T, mean xi (first bundle of the sensor).
double Truth(const mjModel* m, const mjData* d, int sensor, int value) {
  return d->sensordata[m->sensor_adr[sensor] + value];
}

// Steps d to time t_end, setting ctrl[0] = ctrl(time) before each step; returns force trace.
std::vector<double> RunForce(const mjModel* m, mjData* d, double t_end,
                             const std::function<double(double)>& ctrl) {
  std::vector<double> f;
  while (d->time < t_end - 0.5 * m->opt.timestep) {
    d->ctrl[0] = ctrl(d->time);
    mj_step(m, d);
    f.push_back(d->actuator_force[0]);
  }
  return f;
}

// The MuJoCo-free reference: SmaBundle at a fixed unit extension.
struct Reference {
  SmaBundle bundle;
  std::vector<double> s;
  double stretch;
  static Reference Make(const std::string& config_text, double dt, std::uint64_t seed) {
    auto cfg = BundleConfig::FromText("bundle", config_text);
    EXPECT_TRUE(cfg.ok()) << cfg.error();
    auto b = SmaBundle::Create(*cfg, dt);
    EXPECT_TRUE(b.ok());
    Reference r{std::move(b).value(), {}, cfg->unit.prestretch};
    r.s.assign(r.bundle.state_size(), 0.0);
    r.bundle.Reset(r.s.data(), Rng::DeriveSeed(seed, 0), r.stretch);
    return r;
  }
};

struct StepFigures {
  double steady = 0, t75 = -1, settled = 0;
};
// Figures of a step switched on at t_on (trace sampled every dt from dt on).
StepFigures Figures(const std::vector<double>& f, double dt, double t_on) {
  StepFigures s;
  s.steady = f.back();
  for (size_t i = 0; i < f.size(); ++i) {
    const double t = (i + 1) * dt - t_on;
    if (t <= 0) continue;
    if (s.t75 < 0 && f[i] >= 0.75 * s.steady) s.t75 = t;
    if (std::abs(f[i] - s.steady) > 0.05 * s.steady) s.settled = t;
  }
  return s;
}

// (a) The paper's Fig. 4 from a stock host: ctrl held at 1 from t = 1 s gives the force trace of
// the MuJoCo-free bundle switched on once at 1 s, at the fixed extension of a rigid bench.
TEST(EnginePlugin, CtrlHeldAtOneGivesTheFig4TraceOfTheMujocoFreeBundle) {
  ModelPtr m = MustLoad(BenchXml({ConfigXml("units", "60"), "bundle", "tendon=\"bundle\"",
                                  "ctrlrange=\"-1 1\"", "Euler", /*fixed=*/true}));
  ASSERT_NE(m, nullptr);
  ASSERT_EQ(m->nq, 0);
  DataPtr d(mj_makeData(m.get()));
  const double dt = m->opt.timestep;
  Reference ref = Reference::Make("units=60", dt, /*seed=*/0);

  double max_diff = 0;
  std::vector<double> trace;
  int step = 0;
  while (d->time < 8.0 - 0.5 * dt) {
    const double t = step * dt;
    d->ctrl[0] = t >= 1.0 - 1e-9 ? 1.0 : 0.0;
    mj_step(m.get(), d.get());
    // mj_step's forward pass used the units' state at the step's start; then they advanced.
    const double expected = ref.bundle.Tension(ref.s.data(), ref.stretch);
    if (step == 1000) {
      ASSERT_TRUE(ref.bundle.Broadcast(ref.s.data(), 1, 0, ref.stretch).ok());
    }
    ref.bundle.Advance(ref.s.data(), ref.stretch, dt);
    max_diff = std::max(max_diff, std::abs(-d->actuator_force[0] - expected));
    trace.push_back(-d->actuator_force[0]);
    ++step;
  }
  mj_forward(m.get(), d.get());
  EXPECT_LE(max_diff, 1e-9);
  EXPECT_NEAR(-d->actuator_force[0], ref.bundle.Tension(ref.s.data(), ref.stretch), 1e-9);
  EXPECT_EQ(Truth(m.get(), d.get(), 0, 0), 60);  // every unit on
  // The paper's Fig. 4 bands (docs/sma-units.md: 26.8 N, 75 % at 2.06 s, settled 2.3 s).
  const StepFigures fig = Figures(trace, dt, 1.0);
  EXPECT_GE(fig.steady, 25.0);
  EXPECT_LE(fig.steady, 30.0);
  EXPECT_GE(fig.t75, 1.5);
  EXPECT_LE(fig.t75, 2.5);
  EXPECT_GT(fig.settled, fig.t75);
  EXPECT_LE(fig.settled, 6.0);
  // Nothing happened before the switch: no force at all for the first second.
  for (int i = 0; i < 1000; ++i) ASSERT_EQ(trace[i], 0.0) << i;
}

// (a) The shipped bench file, loaded from disk: the load cell gives way by tension / 1e6 N/m,
// so the units are a few tens of micrometres shorter than on the rigid bench: the force stays
// within 1 % below the rigid reference.
TEST(EnginePlugin, IsometricBenchFileFollowsTheRigidReferenceWithinOnePercent) {
  testing::LoadPluginLibrary();
  char err[1000] = "";
  ModelPtr m(
      mj_loadXML(RECRUIT_SOURCE_DIR "/models/isometric_bench.xml", nullptr, err, sizeof err));
  ASSERT_NE(m, nullptr) << err;
  DataPtr d(mj_makeData(m.get()));
  const double dt = m->opt.timestep;
  Reference ref = Reference::Make("units=60", dt, 0);
  std::vector<double> f = RunForce(m.get(), d.get(), 6.0, [](double t) { return t >= 1.0 - 1e-9; });
  std::vector<double> r;
  for (int i = 0; i < static_cast<int>(f.size()); ++i) {
    r.push_back(ref.bundle.Tension(ref.s.data(), ref.stretch));
    if (i == 1000) {
      ASSERT_TRUE(ref.bundle.Broadcast(ref.s.data(), 1, 0, ref.stretch).ok());
    }
    ref.bundle.Advance(ref.s.data(), ref.stretch, dt);
  }
  for (size_t i = 0; i < f.size(); ++i) {
    ASSERT_LE(-f[i], r[i] + 1e-9) << "step " << i;
    ASSERT_GE(-f[i], 0.99 * r[i] - 1e-6) << "step " << i;
  }
  EXPECT_GT(r.back(), 25.0);
}

// (a) ctrl = 0 draws nothing and switches nothing: a run with broadcasts only at 0.5 s and 1.5 s
// (ctrl 0.5) and 0 in between equals the reference that broadcasts exactly twice, bit for bit
// in the random stream, and the stream's words do not move while ctrl is 0.
TEST(EnginePlugin, CtrlZeroChangesNothing) {
  ModelPtr m = MustLoad(BenchXml({ConfigXml("units", "60") + ConfigXml("seed", "7"), "bundle",
                                  "tendon=\"bundle\"", "", "Euler", true}));
  ASSERT_NE(m, nullptr);
  DataPtr d(mj_makeData(m.get()));
  const double dt = m->opt.timestep;
  Reference ref = Reference::Make("units=60", dt, 7);
  const int n = static_cast<int>(ref.s.size());
  // 1000 steps of ctrl 0 from reset: the block is the reference's after 1000 Advance calls
  // and no Broadcast (only the block's step counter moves; no unit switches, no draws).
  const std::vector<double> initial(Block(m.get(), d.get(), 0, 0, n),
                                    Block(m.get(), d.get(), 0, 0, n) + n);
  ASSERT_TRUE(SameBits(ref.s.data(), initial.data(), n));
  for (int i = 0; i < 1000; ++i) {
    mj_step(m.get(), d.get());
    ref.bundle.Advance(ref.s.data(), ref.stretch, dt);
  }
  EXPECT_TRUE(SameBits(ref.s.data(), Block(m.get(), d.get(), 0, 0, n), n));
  EXPECT_TRUE(SameBits(initial.data() + 1, Block(m.get(), d.get(), 0, 0, n) + 1, 4));  // stream
  EXPECT_EQ(d->actuator_force[0], 0.0);
  ref = Reference::Make("units=60", dt, 7);
  mj_resetData(m.get(), d.get());
  std::vector<double> rng_before(4);
  for (int step = 0; step < 2500; ++step) {
    const bool broadcast = step == 500 || step == 1500;
    d->ctrl[0] = broadcast ? 0.5 : 0.0;
    const double* blk = Block(m.get(), d.get(), 0, 0, n);
    std::copy(blk + 1, blk + 5, rng_before.begin());
    mj_step(m.get(), d.get());
    if (broadcast) {
      ASSERT_TRUE(ref.bundle.Broadcast(ref.s.data(), 0.5, 0, ref.stretch).ok());
    }
    ref.bundle.Advance(ref.s.data(), ref.stretch, dt);
    if (!broadcast) {
      ASSERT_TRUE(SameBits(rng_before.data(), blk + 1, 4)) << "step " << step;
    }
    ASSERT_TRUE(SameBits(ref.s.data(), blk, n)) << "step " << step;
  }
  const int on = ref.bundle.OnCount(ref.s.data());
  EXPECT_GT(on, 30);  // two draws at p = 0.5: 75 % expected
  EXPECT_LT(on, 60);
}

// (b) Each bad declaration makes MuJoCo's compiler fail with a message naming the actuator,
// the key and the value, and what is allowed.
struct BadCase {
  std::string label;
  Bench bench;
  std::vector<std::string> expected;  // substrings of the compiler's message
};

TEST(EnginePlugin, CompileErrorNamesActuatorKeyAndValue) {
  auto bench = [](std::string config, std::string target = "tendon=\"bundle\"",
                  std::string extra = "") {
    return Bench{config, "biceps", target, extra, "Euler", false};
  };
  const std::vector<BadCase> cases = {
      {"bad number",
       bench(ConfigXml("units", "sixty")),
       {"biceps", "units=sixty", "not a finite number"}},
      {"out of range",
       bench(ConfigXml("current", "-0.1")),
       {"biceps", "current=-0.1", "[0, 100] A"}},
      {"not whole", bench(ConfigXml("series", "1.5")), {"biceps", "series=1.5", "whole number"}},
      {"bad law", bench(ConfigXml("law", "rope")), {"biceps", "law=rope", "wire, spring"}},
      {"bad seed", bench(ConfigXml("seed", "-3")), {"biceps", "seed=-3", "whole number"}},
      {"bad period",
       bench(ConfigXml("broadcast_period", "soon")),
       {"biceps", "broadcast_period=soon", "[0, 1e6]"}},
      {"joint transmission",
       bench("", "joint=\"load_cell\""),
       {"biceps", "joint='load_cell'", "must act on a tendon"}},
      {"gear", bench("", "tendon=\"bundle\"", "gear=\"-2\""), {"biceps", "gear=-2", "must be > 0"}},
      {"bad unit model",
       bench(ConfigXml("unit_model", "tabulated")),
       {"biceps", "unit_model=tabulated", "exact, binned"}},
      {"bins without binned",
       bench(ConfigXml("bins", "8")),
       {"biceps", "bins=8", "is for unit_model=binned"}},
  };
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.label);
    auto m = Load(BenchXml(c.bench));
    ASSERT_FALSE(m.ok());
    for (const std::string& s : c.expected) EXPECT_THAT(m.error(), HasSubstr(s));
  }
  // An undeclared key is rejected by MuJoCo's own parser, which names key and plugin.
  auto m = Load(BenchXml(bench(ConfigXml("colour", "red"))));
  ASSERT_FALSE(m.ok());
  EXPECT_THAT(m.error(), AllOf(HasSubstr("colour"), HasSubstr("recruit.sma")));
}

// A run with switching in both directions, for the fork/reset/thread tests: ctrl follows a
// fixed schedule of signed broadcasts.
double Schedule(double t, double phase) {
  const int k = static_cast<int>(std::floor((t + phase) / 0.05));
  switch (k % 7) {
    case 0:
      return 0.3;
    case 2:
      return -0.2;
    case 4:
      return 0.6;
    case 5:
      return -0.5;
    default:
      return 0.0;
  }
}

struct Snapshot {
  std::vector<double> state;
  static Snapshot Of(const mjModel* m, const mjData* d) {
    Snapshot s;
    s.state.resize(mj_stateSize(m, mjSTATE_FULLPHYSICS));
    mj_getState(m, d, s.state.data(), mjSTATE_FULLPHYSICS);
    return s;
  }
  bool operator==(const Snapshot& o) const {
    return state.size() == o.state.size() &&
           SameBits(state.data(), o.state.data(), static_cast<long>(state.size()));
  }
};

// Steps d for `steps` steps under Schedule, recording the full physics state after each.
std::vector<Snapshot> Continue(const mjModel* m, mjData* d, int steps, double phase = 0) {
  std::vector<Snapshot> out;
  for (int i = 0; i < steps; ++i) {
    d->ctrl[0] = Schedule(d->time, phase);
    mj_step(m, d);
    out.push_back(Snapshot::Of(m, d));
  }
  return out;
}

std::string SwitchingBench() {
  return BenchXml(
      {ConfigXml("units", "60") + ConfigXml("seed", "11") + ConfigXml("broadcast_period", "0.01"),
       "bundle", "tendon=\"bundle\"", "", "Euler", false});
}

// unit_model=binned from MJCF: the plugin reads both keys, and after the bundle's merge passes
// (every 8 steps) at most `bins` cohorts remain under switching in both directions, where the
// exact model keeps more.
TEST(EnginePlugin, BinnedUnitModelFromMjcfBoundsTheCohorts) {
  auto most_cohorts = [](const std::string& keys) {
    ModelPtr m = MustLoad(BenchXml({ConfigXml("units", "60") + ConfigXml("seed", "11") +
                                        ConfigXml("broadcast_period", "0.01") + keys,
                                    "bundle", "tendon=\"bundle\"", "", "Euler", false}));
    if (m == nullptr) return -1;
    DataPtr d(mj_makeData(m.get()));
    const int block = SmaBundle::StateSize(60);
    int most = 0;
    for (int i = 0; i < 3000; ++i) {
      d->ctrl[0] = Schedule(d->time, 0);
      mj_step(m.get(), d.get());
      if (i % 8 == 7) {  // just after a merge pass (the bundle's 8th, 16th, ... update)
        most = std::max(most, static_cast<int>(Block(m.get(), d.get(), 0, 0, block)[9]));
      }
    }
    return most;
  };
  EXPECT_GT(most_cohorts(""), 6);
  EXPECT_EQ(most_cohorts(ConfigXml("unit_model", "binned") + ConfigXml("bins", "6")), 6);
}

// (c) mj_copyData mid-run forks the run: both continuations are bit-identical, including a
// copy into an mjData that had run elsewhere.
TEST(EnginePlugin, CopyDataMidRunGivesTwoIdenticalContinuations) {
  ModelPtr m = MustLoad(SwitchingBench());
  ASSERT_NE(m, nullptr);
  DataPtr a(mj_makeData(m.get()));
  DataPtr other(mj_makeData(m.get()));
  Continue(m.get(), a.get(), 1500);
  Continue(m.get(), other.get(), 700, 0.013);  // unrelated history
  ASSERT_GT(Truth(m.get(), a.get(), 0, 0), 0);
  DataPtr b(mj_copyData(nullptr, m.get(), a.get()));
  mj_copyData(other.get(), m.get(), a.get());
  const auto ca = Continue(m.get(), a.get(), 1500);
  const auto cb = Continue(m.get(), b.get(), 1500);
  const auto co = Continue(m.get(), other.get(), 1500);
  for (size_t i = 0; i < ca.size(); ++i) {
    ASSERT_TRUE(ca[i] == cb[i]) << "step " << i;
    ASSERT_TRUE(ca[i] == co[i]) << "step " << i;
  }
  EXPECT_TRUE(SameBits(a->actuator_force, b->actuator_force, m->nu));
}

// (d) mj_resetData (and mj_resetDataKeyframe) restore the initial state exactly, and the run
// after a reset repeats the first one bit for bit (the random stream restarts).
TEST(EnginePlugin, ResetDataRestoresTheInitialStateExactly) {
  ModelPtr m = MustLoad(SwitchingBench());
  ASSERT_NE(m, nullptr);
  DataPtr d(mj_makeData(m.get()));
  const Snapshot initial = Snapshot::Of(m.get(), d.get());
  const auto first = Continue(m.get(), d.get(), 2000);
  ASSERT_FALSE(first.back() == initial);
  mj_resetData(m.get(), d.get());
  EXPECT_TRUE(Snapshot::Of(m.get(), d.get()) == initial);
  const auto second = Continue(m.get(), d.get(), 2000);
  for (size_t i = 0; i < first.size(); ++i) ASSERT_TRUE(first[i] == second[i]) << i;
  mj_resetDataKeyframe(m.get(), d.get(), -1);  // no keyframe: qpos0, like mj_resetData
  EXPECT_TRUE(Snapshot::Of(m.get(), d.get()) == initial);
}

// (e) Two bundles in one model draw from different streams and a broadcast to one leaves the
// other untouched; two models stepped interleaved equal each stepped alone.
TEST(EnginePlugin, BundlesAndModelsNeverShareState) {
  testing::LoadPluginLibrary();
  const std::string two = R"(<mujoco>
  <option timestep="0.001"/>
  <extension><plugin plugin="recruit.sma">
    <instance name="a"><config key="units" value="40"/></instance>
    <instance name="b"><config key="units" value="40"/></instance>
  </plugin></extension>
  <worldbody>
    <site name="s0" pos="0 0 0"/><site name="s1" pos="0.1 0 0"/><site name="s2" pos="0 0.1 0"/>
  </worldbody>
  <tendon>
    <spatial name="t1"><site site="s0"/><site site="s1"/></spatial>
    <spatial name="t2"><site site="s0"/><site site="s2"/></spatial>
  </tendon>
  <actuator>
    <plugin name="agonist" instance="a" tendon="t1"/>
    <plugin name="antagonist" instance="b" tendon="t2"/>
  </actuator>
  <sensor><plugin name="ta" instance="a"/><plugin name="tb" instance="b"/></sensor>
</mujoco>)";
  ModelPtr m = MustLoad(two);
  ASSERT_NE(m, nullptr);
  const int n = SmaBundle::StateSize(40);
  DataPtr d(mj_makeData(m.get()));
  const std::vector<double> b0(Block(m.get(), d.get(), 1, 0, n),
                               Block(m.get(), d.get(), 1, 0, n) + n);
  d->ctrl[0] = 0.5;
  for (int i = 0; i < 300; ++i) mj_step(m.get(), d.get());
  mj_forward(m.get(), d.get());
  EXPECT_GT(Truth(m.get(), d.get(), 0, 0), 0);
  // the other bundle drew nothing and switched nothing: same stream words, same unit states
  const double* b1 = Block(m.get(), d.get(), 1, 0, n);
  EXPECT_TRUE(SameBits(b0.data() + 1, b1 + 1, kRngHalves));
  EXPECT_EQ(Truth(m.get(), d.get(), 1, 0), 0);
  EXPECT_TRUE(SameBits(b0.data() + kHeader, b1 + kHeader, n - kHeader));
  // Same config and seed, different bundle index: different streams.
  mj_resetData(m.get(), d.get());
  d->ctrl[0] = d->ctrl[1] = 0.3;
  mj_step(m.get(), d.get());
  EXPECT_FALSE(SameBits(Block(m.get(), d.get(), 0, 0, n) + 1, Block(m.get(), d.get(), 1, 0, n) + 1,
                        kRngHalves));
  EXPECT_FALSE(SameBits(Block(m.get(), d.get(), 0, 0, n) + kHeader + 7 * 40,
                        Block(m.get(), d.get(), 1, 0, n) + kHeader + 7 * 40, 40));

  // Two models (a copy of the first, and a different one), stepped interleaved.
  ModelPtr m2(mj_copyModel(nullptr, m.get()));
  ModelPtr m3 = MustLoad(SwitchingBench());
  ASSERT_NE(m3, nullptr);
  auto solo = [](const mjModel* mm, int steps) {
    DataPtr dd(mj_makeData(mm));
    return Continue(mm, dd.get(), steps);
  };
  const auto alone2 = solo(m2.get(), 500);
  const auto alone3 = solo(m3.get(), 500);
  DataPtr d2(mj_makeData(m2.get())), d3(mj_makeData(m3.get()));
  for (int i = 0; i < 500; ++i) {
    ASSERT_TRUE(Continue(m2.get(), d2.get(), 1)[0] == alone2[i]) << i;
    ASSERT_TRUE(Continue(m3.get(), d3.get(), 1)[0] == alone3[i]) << i;
  }
}

// (e) One mjData per thread, two threads: every run equals the serial run bit for bit.
TEST(EnginePlugin, OneDataPerThreadEqualsSerialBitForBit) {
  ModelPtr m = MustLoad(SwitchingBench());
  ASSERT_NE(m, nullptr);
  constexpr int kRuns = 4, kSteps = 1500;
  auto run = [&](int r) {
    DataPtr d(mj_makeData(m.get()));
    return Continue(m.get(), d.get(), kSteps, 0.011 * r);
  };
  std::vector<std::vector<Snapshot>> serial(kRuns), parallel(kRuns);
  for (int r = 0; r < kRuns; ++r) serial[r] = run(r);
  std::vector<std::thread> threads;
  for (int t = 0; t < 2; ++t) {
    threads.emplace_back([&, t] {
      for (int r = t; r < kRuns; r += 2) parallel[r] = run(r);
    });
  }
  for (auto& t : threads) t.join();
  for (int r = 0; r < kRuns; ++r) {
    for (int i = 0; i < kSteps; ++i) ASSERT_TRUE(serial[r][i] == parallel[r][i]) << r << " " << i;
  }
  EXPECT_FALSE(serial[0].back() == serial[1].back());  // the schedules differ
}

// (g) mj_getState / mj_setState with mjSTATE_FULLPHYSICS carry the units: restoring a saved
// state into a fresh mjData continues exactly as the original.
TEST(EnginePlugin, GetStateSetStateRoundTrips) {
  ModelPtr m = MustLoad(SwitchingBench());
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(mj_stateSize(m.get(), mjSTATE_PLUGIN), m->npluginstate);
  DataPtr d(mj_makeData(m.get()));
  Continue(m.get(), d.get(), 1200);
  const Snapshot saved = Snapshot::Of(m.get(), d.get());
  const auto original = Continue(m.get(), d.get(), 1000);
  DataPtr fresh(mj_makeData(m.get()));
  mj_setState(m.get(), fresh.get(), saved.state.data(), mjSTATE_FULLPHYSICS);
  EXPECT_TRUE(Snapshot::Of(m.get(), fresh.get()) == saved);
  const auto restored = Continue(m.get(), fresh.get(), 1000);
  for (size_t i = 0; i < original.size(); ++i) ASSERT_TRUE(original[i] == restored[i]) << i;
  // Back into the same mjData too.
  mj_setState(m.get(), d.get(), saved.state.data(), mjSTATE_FULLPHYSICS);
  EXPECT_TRUE(Continue(m.get(), d.get(), 1000).back() == original.back());
}

// (h) The signed convention: ctrl = -1 switches every on unit off at the next broadcast.
TEST(EnginePlugin, CtrlMinusOneSwitchesEveryUnitOff) {
  ModelPtr m = MustLoad(
      BenchXml({ConfigXml("units", "60"), "bundle", "tendon=\"bundle\"", "", "Euler", true}));
  ASSERT_NE(m, nullptr);
  DataPtr d(mj_makeData(m.get()));
  d->ctrl[0] = 1;
  for (int i = 0; i < 2000; ++i) mj_step(m.get(), d.get());
  mj_forward(m.get(), d.get());
  ASSERT_EQ(Truth(m.get(), d.get(), 0, 0), 60);
  d->ctrl[0] = -1;
  mj_step(m.get(), d.get());
  mj_forward(m.get(), d.get());
  EXPECT_EQ(Truth(m.get(), d.get(), 0, 0), 0);
  d->ctrl[0] = -0.5;  // nothing left to switch off
  mj_step(m.get(), d.get());
  mj_forward(m.get(), d.get());
  EXPECT_EQ(Truth(m.get(), d.get(), 0, 0), 0);
}

// (h) ctrl = 0.3 held with broadcast_period 0.5: units draw only at t = 0, 0.5, 1.0, ...; after
// k broadcasts the on count is Binomial(60, 1 - 0.7^k). Over 200 seeds the mean and variance of
// the counts after 1 and after 3 broadcasts fall within 4.5 standard errors of the binomial's
// (a broadcast every step would give 60 units on; one draw for the whole bundle a variance 60x
// too large).
TEST(EnginePlugin, HeldCtrlBroadcastsAtThePeriodWithBinomialCounts) {
  constexpr int kSeeds = 200, kUnits = 60;
  std::vector<double> c1, c3;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    ModelPtr m =
        MustLoad(BenchXml({ConfigXml("units", "60") + ConfigXml("seed", std::to_string(seed)) +
                               ConfigXml("broadcast_period", "0.5"),
                           "bundle", "tendon=\"bundle\"", "", "Euler", true}));
    ASSERT_NE(m, nullptr);
    DataPtr d(mj_makeData(m.get()));
    int last = 0, changes = 0;
    for (int step = 0; step < 1200; ++step) {  // t = 0 .. 1.2 s
      d->ctrl[0] = 0.3;
      mj_step(m.get(), d.get());
      mj_forward(m.get(), d.get());
      const int on = static_cast<int>(Truth(m.get(), d.get(), 0, 0));
      if (on != last) {
        ++changes;
        ASSERT_TRUE(step == 0 || step == 500 || step == 1000) << "count changed at step " << step;
      }
      last = on;
      if (step == 400) c1.push_back(on);
    }
    c3.push_back(last);
  }
  auto check = [&](const std::vector<double>& c, double p) {
    double mean = 0, var = 0;
    for (double x : c) mean += x / c.size();
    for (double x : c) var += (x - mean) * (x - mean) / (c.size() - 1);
    const double mu = kUnits * p, sigma2 = kUnits * p * (1 - p);
    // standard error of the sample variance: sigma2 sqrt(2 / (n - 1)) (normal approximation)
    EXPECT_NEAR(mean, mu, 4.5 * std::sqrt(sigma2 / c.size())) << "p = " << p;
    EXPECT_NEAR(var, sigma2, 4.5 * sigma2 * std::sqrt(2.0 / (c.size() - 1))) << "p = " << p;
  };
  check(c1, 0.3);
  check(c3, 1 - 0.7 * 0.7 * 0.7);
}

}  // namespace file_engine_plugin_test
}  // namespace recruit::sma
