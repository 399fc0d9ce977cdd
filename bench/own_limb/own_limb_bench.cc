// Bundles on the limbs users bring (issue 29): a model as shipped, with its MuJoCo muscles,
// against the same model after `recruit attach` with the default sizing (attach::Attach, run
// once per process into a temporary folder), side by side in one run so that the ratio holds on
// a shared, noisy machine.
//  - BM_OwnLimbStep: mj_step of both models under one broadcast pattern, interleaved in blocks of
//    1000 steps; counter "ratio" = bundles' CPU time / muscles' CPU time. Fig. 4 step: every
//    bundle all on for 10 s, all off for 6 s (the muscles' ctrl 1 / 0); random switching: every
//    bundle p_on = p_off = 0.1 every 0.5 s (each muscle's ctrl follows its bundle's on fraction).
//  - BM_OwnLimbClosedLoop: the attached model's starter task as `recruit simulate` runs it
//    (sim::RunTask: bundles, Kalman filter, self-tuned outer loop; model load included) against
//    the muscle model loaded and driven to the same joint targets by a PD law on the joint angle
//    (each muscle's ctrl from the torque it can give, through its moment arm), interleaved run by
//    run; counter "ratio" = the closed loop's CPU time / the muscle loop's.
// Limbs: MyoSuite's myoelbow_1dof6muscles, located at run time in the installed myo-sim package
// (RECRUIT_MYO_SIM = its folder, else the checkout's .venv, else python3; skipped with a message
// when absent; nothing of it is copied into the repository), and the project's own two-joint arm
// models/arm2j_muscle.xml (in place of arm26, which nothing here installs).
#include <benchmark/benchmark.h>
#include <mujoco/mujoco.h>
#include <stdlib.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "attach/attach.h"
#include "plugin/sma_host.h"
#include "sim/run_task.h"
#include "sim/task.h"

namespace recruit {
namespace {

double ThreadCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

std::string Trim(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
  return s;
}

std::string Run(const std::string& command) {
  std::string out;
  if (std::FILE* p = popen(command.c_str(), "r")) {
    char buf[512];
    while (std::fgets(buf, sizeof buf, p) != nullptr) out += buf;
    pclose(p);
  }
  return Trim(out);
}

// The installed myo-sim package's folder, or "" when none is found.
std::string MyoSimDir() {
  if (const char* d = std::getenv("RECRUIT_MYO_SIM"); d != nullptr && *d != 0) return d;
  const std::string probe =
      " -c 'import myo_sim,os;print(os.path.dirname(myo_sim.__file__))' 2>/dev/null";
  std::string dir = Run("'" RECRUIT_SOURCE_DIR "/.venv/bin/python'" + probe);
  if (dir.empty()) dir = Run("python3" + probe);
  return dir;
}

// Every bundle config of the attached model `xml` (a <config key="units" .../> each) gets the
// config lines `keys` after its units; `knob` names the variable in errors.
Status InsertKeys(const std::string& xml, const std::string& keys, const char* knob) {
  std::ifstream in(xml);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  int n = 0;
  for (auto at = text.find("key=\"units\""); at != std::string::npos;
       at = text.find("key=\"units\"", at + 1)) {
    const auto end = text.find("/>", at);
    if (end == std::string::npos) break;
    text.insert(end + 2, keys);
    ++n;
  }
  if (n == 0) return Error{std::string(knob) + ": no units config in " + xml};
  std::ofstream(xml, std::ios::trunc) << text;
  return Status::Ok();
}

std::string ConfigLine(const std::string& key, const std::string& value) {
  return "<config key=\"" + key + "\" value=\"" + value + "\"/>";
}

// RECRUIT_BENCH_MERGE="T,XI" (an experiment, not the default): every bundle of the attached model
// gets merge_temperature T and merge_xi XI (plugin/README.md), for the cost of fewer cohorts.
Status LoosenMerge(const std::string& xml) {
  const char* merge = std::getenv("RECRUIT_BENCH_MERGE");
  if (merge == nullptr || *merge == 0) return Status::Ok();
  const std::string m = merge;
  const auto comma = m.find(',');
  if (comma == std::string::npos) return Error{"RECRUIT_BENCH_MERGE: expected T,XI, got " + m};
  return InsertKeys(xml,
                    ConfigLine("merge_temperature", m.substr(0, comma)) +
                        ConfigLine("merge_xi", m.substr(comma + 1)),
                    "RECRUIT_BENCH_MERGE");
}

// RECRUIT_BENCH_KEYS="key=value ..." (an experiment, not the default): every bundle of the
// attached model gets those config keys, e.g. "unit_model=binned bins=16" or
// "update_period=0.01" (plugin/README.md).
Status AddKeys(const std::string& xml) {
  const char* given = std::getenv("RECRUIT_BENCH_KEYS");
  if (given == nullptr || *given == 0) return Status::Ok();
  std::istringstream pairs(given);
  std::string keys;
  for (std::string pair; pairs >> pair;) {
    const auto eq = pair.find('=');
    if (eq == std::string::npos || eq == 0) {
      return Error{"RECRUIT_BENCH_KEYS: expected key=value pairs, got " + pair};
    }
    keys += ConfigLine(pair.substr(0, eq), pair.substr(eq + 1));
  }
  return InsertKeys(xml, keys, "RECRUIT_BENCH_KEYS");
}

struct Limb {
  std::string muscle_xml, attached_xml, task_json;
};

// The limb's muscle model and its attached copy with the starter task (made once per process).
Result<Limb> Prepare(const std::string& name) {
  static std::map<std::string, Result<Limb>> made;
  if (auto it = made.find(name); it != made.end()) return it->second;
  Limb limb;
  if (name == "myoelbow") {
    const std::string dir = MyoSimDir();
    limb.muscle_xml = dir + "/models/legacy/elbow/myoelbow_1dof6muscles.xml";
    if (dir.empty() || !std::ifstream(limb.muscle_xml)) {
      return made
          .emplace(name, Error{"MyoSuite's elbow not found (myo-sim is not installed: "
                               "scripts/install-deps.sh, or set RECRUIT_MYO_SIM)"})
          .first->second;
    }
  } else {
    limb.muscle_xml = RECRUIT_SOURCE_DIR "/models/arm2j_muscle.xml";
  }
  char tmpl[] = "/tmp/recruit_own_limb_XXXXXX";
  if (mkdtemp(tmpl) == nullptr) return Error{"cannot make a temporary folder"};
  // Removed when the program ends.
  static std::vector<std::string> folders;
  if (folders.empty()) {
    std::atexit([] {
      for (const std::string& f : folders) std::filesystem::remove_all(f);
    });
  }
  folders.push_back(tmpl);
  attach::AttachOptions o;
  o.model = limb.muscle_xml;
  o.muscles = {"all"};
  o.output = std::string(tmpl) + "/" + name + "_sma.xml";
  o.task = std::string(tmpl) + "/steps.json";
  auto r = attach::Attach(o);
  if (!r.ok()) return made.emplace(name, Error{"attach: " + r.error()}).first->second;
  if (Status s = LoosenMerge(o.output); !s) return made.emplace(name, s.failure()).first->second;
  if (Status s = AddKeys(o.output); !s) return made.emplace(name, s.failure()).first->second;
  limb.attached_xml = o.output;
  limb.task_json = o.task;
  return made.emplace(name, limb).first->second;
}

mjModel* Load(const std::string& path, benchmark::State& state) {
  char err[1000] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, err, sizeof err);
  if (m == nullptr) state.SkipWithError((path + ": " + err).c_str());
  return m;
}

const char* kLimbs[] = {"myoelbow", "arm2j"};

// Steps of both models under one broadcast pattern (see the top of the file).
void BM_OwnLimbStep(benchmark::State& state) {
  const std::string name = kLimbs[state.range(0)];
  const bool fig4 = state.range(1) == 0;
  auto limb = Prepare(name);
  if (!limb.ok()) return state.SkipWithError(limb.error().c_str());
  mjModel* mm = Load(limb->muscle_xml, state);
  mjModel* ms = mm ? Load(limb->attached_xml, state) : nullptr;
  if (ms == nullptr) return mj_deleteModel(mm);
  auto host = sma::SmaHost::Create(ms);
  mjData* dm = mj_makeData(mm);
  mjData* ds = mj_makeData(ms);
  (*host)->Reset(ds, 1);
  const int nb = (*host)->num_bundles();
  std::vector<int> muscle(nb);  // each bundle's muscle in the muscle model (same name)
  for (int b = 0; b < nb; ++b) {
    muscle[b] = mj_name2id(mm, mjOBJ_ACTUATOR, (*host)->bundle_name(b).c_str());
  }
  const long steps_on = std::lround(10 / ms->opt.timestep),
             cycle = std::lround(16 / ms->opt.timestep),
             every = std::lround(0.5 / ms->opt.timestep);
  std::vector<double> fraction(nb, 0);
  double t_muscle = 0, t_sma = 0, units = 0;
  long im = 0, is = 0;
  for (int b = 0; b < nb; ++b) units += (*host)->num_units(b);
  for (auto _ : state) {
    const double t0 = ThreadCpuSeconds();
    for (int k = 0; k < 1000; ++k, ++im) {
      if (fig4 ? im % cycle == 0 || im % cycle == steps_on : im % every == 0) {
        for (int b = 0; b < nb; ++b) {
          if (muscle[b] >= 0) dm->ctrl[muscle[b]] = fig4 ? (im % cycle == 0 ? 1 : 0) : fraction[b];
        }
      }
      mj_step(mm, dm);
    }
    const double t1 = ThreadCpuSeconds();
    for (int k = 0; k < 1000; ++k, ++is) {
      if (fig4 ? is % cycle == 0 || is % cycle == steps_on : is % every == 0) {
        for (int b = 0; b < nb; ++b) {
          if (fig4) {
            (void)(*host)->Broadcast(ds, b, is % cycle == 0 ? 1 : 0, is % cycle == 0 ? 0 : 1);
          } else {
            (void)(*host)->Broadcast(ds, b, 0.1, 0.1);
            fraction[b] = (*host)->OnCount(ds, b) / double((*host)->num_units(b));
          }
        }
      }
      mj_step(ms, ds);
    }
    t_muscle += t1 - t0;
    t_sma += ThreadCpuSeconds() - t1;
  }
  double cohorts = 0;
  for (int b = 0; b < nb; ++b) cohorts += (*host)->NumCohorts(ds, b);
  state.counters["ratio"] = t_sma / t_muscle;
  state.counters["muscle_us_per_step"] = 1e6 * t_muscle / (1000.0 * state.iterations());
  state.counters["sma_us_per_step"] = 1e6 * t_sma / (1000.0 * state.iterations());
  state.counters["bundles"] = nb;
  state.counters["units"] = units;
  state.counters["cohorts_at_end"] = cohorts;
  state.SetLabel(name + (fig4 ? " fig4_step" : " random_switching"));
  mj_deleteData(dm);
  mj_deleteData(ds);
  host->reset();
  mj_deleteModel(mm);
  mj_deleteModel(ms);
}
BENCHMARK(BM_OwnLimbStep)
    ->ArgNames({"limb", "regime"})
    ->Args({0, 0})
    ->Args({0, 1})
    ->Args({1, 0})
    ->Args({1, 1})
    ->Iterations(48)  // 48000 steps: 96 simulated seconds at 2 ms, six Fig. 4 cycles
    ->Unit(benchmark::kMillisecond);

// A joint the starter task drives, with its reference steps (rad).
struct Target {
  int qpos = -1, dof = -1;
  double initial = 0;
  std::vector<double> times, values;
  double At(double t) const {
    double v = initial;
    for (std::size_t i = 0; i < times.size() && times[i] <= t; ++i) v = values[i];
    return v;
  }
};

std::vector<Target> Targets(const mjModel* m, const nlohmann::json& task) {
  std::vector<Target> out;
  for (const auto& j : task.at("joints")) {
    const int id = mj_name2id(m, mjOBJ_JOINT, j.at("joint").get<std::string>().c_str());
    const auto& r = j.at("reference");
    const double scale = r.value("unit", "rad") == "deg" ? M_PI / 180 : 1;
    Target t;
    t.qpos = m->jnt_qposadr[id];
    t.dof = m->jnt_dofadr[id];
    t.initial = scale * r.at("initial").get<double>();
    for (double x : r.at("times")) t.times.push_back(x);
    for (double x : r.at("values")) t.values.push_back(scale * x);
    out.push_back(t);
  }
  return out;
}

// The muscle model's own loop: loaded, started at the targets' initial pose and driven for
// `duration` by a PD law per driven joint; each muscle's ctrl is the torque demand it can serve
// (minus its moment arm on the joint, normalised), clamped to [0, 1]. Returns the number of steps.
long MuscleLoop(const std::string& xml, const nlohmann::json& task, double duration) {
  char err[1000];
  mjModel* m = mj_loadXML(xml.c_str(), nullptr, err, sizeof err);
  if (m == nullptr) return -1;
  mjData* d = mj_makeData(m);
  const std::vector<Target> targets = Targets(m, task);
  for (const Target& t : targets) d->qpos[t.qpos] = t.initial;
  // Moment arms (dL/dq) at the start pose, by central differences of the actuator lengths.
  std::vector<double> arm(targets.size() * m->nu);
  for (std::size_t j = 0; j < targets.size(); ++j) {
    const double q = d->qpos[targets[j].qpos], h = 1e-4;
    d->qpos[targets[j].qpos] = q + h;
    mj_forward(m, d);
    std::vector<double> up(d->actuator_length, d->actuator_length + m->nu);
    d->qpos[targets[j].qpos] = q - h;
    mj_forward(m, d);
    for (int a = 0; a < m->nu; ++a) arm[j * m->nu + a] = (up[a] - d->actuator_length[a]) / (2 * h);
    d->qpos[targets[j].qpos] = q;
  }
  mj_forward(m, d);
  const double kp = 20, kd = 2;  // activation per rad, per rad/s (times the normalised arm)
  std::vector<double> log;
  log.reserve(4 * static_cast<std::size_t>(duration / m->opt.timestep + 2));
  long n = 0;
  while (d->time < duration) {
    for (int a = 0; a < m->nu; ++a) {
      double u = 0;
      for (std::size_t j = 0; j < targets.size(); ++j) {
        const Target& t = targets[j];
        const double demand =
            kp * (t.At(d->time) - d->qpos[t.qpos]) - kd * d->qvel[t.dof];  // torque sign
        u += -arm[j * m->nu + a] * demand / 0.02;  // a 20 mm arm counts as 1
      }
      d->ctrl[a] = std::clamp(u, 0.0, 1.0);
    }
    mj_step(m, d);
    log.push_back(d->time);
    for (const Target& t : targets) log.push_back(d->qpos[t.qpos]);
    ++n;
  }
  benchmark::DoNotOptimize(log.data());
  mj_deleteData(d);
  mj_deleteModel(m);
  return n;
}

void BM_OwnLimbClosedLoop(benchmark::State& state) {
  const std::string name = kLimbs[state.range(0)];
  auto limb = Prepare(name);
  if (!limb.ok()) return state.SkipWithError(limb.error().c_str());
  auto task = sim::Task::FromFile(limb->task_json);
  if (!task.ok()) return state.SkipWithError(task.error().c_str());
  nlohmann::json json;
  std::ifstream(limb->task_json) >> json;
  const double duration = json.at("duration").get<double>();
  sim::RunOptions o;
  o.identify_missing_models = true;  // the first run identifies (cached), before timing
  o.quiet = true;
  o.duration = 1;
  if (auto r = sim::RunTask(*task, o); !r.ok()) return state.SkipWithError(r.error().c_str());
  o.duration = duration;
  double t_loop = 0, t_muscle = 0, simulated = 0;
  for (auto _ : state) {
    const double t0 = ThreadCpuSeconds();
    auto r = sim::RunTask(*task, o);
    const double t1 = ThreadCpuSeconds();
    if (!r.ok()) return state.SkipWithError(r.error().c_str());
    if (MuscleLoop(limb->muscle_xml, json, duration) < 0) {
      return state.SkipWithError("muscle model does not load");
    }
    t_loop += t1 - t0;
    t_muscle += ThreadCpuSeconds() - t1;
    simulated += duration;
    ++o.seed;
  }
  state.counters["ratio"] = t_loop / t_muscle;
  state.counters["loop_x_real_time"] = simulated / t_loop;
  state.counters["muscle_x_real_time"] = simulated / t_muscle;
  state.SetLabel(name);
}
BENCHMARK(BM_OwnLimbClosedLoop)
    ->ArgName("limb")
    ->Arg(0)
    ->Arg(1)
    ->Iterations(5)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace recruit
