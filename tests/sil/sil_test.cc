// `recruit sil` end to end (docs/sil.md): the exported package, built natively with
// examples/sil/sil_controller.c, closes the loop over UDP and over a pseudo-terminal; with the
// same seed the run's metrics equal `recruit simulate`'s. Injected faults are counted as the
// protocol says; a missing controller and a wrong dT end the run with their exit codes. Every
// process runs under a time limit.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <thread>

namespace file_sil_test {

namespace fs = std::filesystem;
const std::string kRecruit = RECRUIT_BIN;
// Tasks by their path in the source tree without ".json". The arm: tests/export/data's copy of
// arm_reach_hold with hand-set gains (recruit sil drives hand-set and force tasks only; the
// shipped arm tasks run the self-tuned loop).
const std::string kArmTask = "tests/export/data/arm_reach_hold_hand";
const std::string kStepsTask = "models/tasks/isometric_steps";
std::string TaskFile(const std::string& task) {
  return std::string(RECRUIT_SOURCE_DIR) + "/" + task + ".json";
}

// This process's scratch folder, removed when the process ends (ctest runs each test in a
// process of its own, so every one would otherwise leave a folder in the temp directory).
struct ScratchDir {
  fs::path path = fs::temp_directory_path() / ("recruit_sil_test_" + std::to_string(::getpid()));
  ScratchDir() { fs::create_directories(path); }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};
fs::path Dir() {
  static const ScratchDir d;
  return d.path;
}

int Shell(const std::string& cmd) {
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : 128;
}

std::string ReadText(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A background `recruit sil`; its stdout and stderr go to `log`.
struct Plant {
  pid_t pid = -1;
  fs::path log;
  int Wait(double seconds) {  // exit code; kills it (and fails) past `seconds`
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    int status = 0;
    while (::waitpid(pid, &status, WNOHANG) == 0) {
      if (std::chrono::steady_clock::now() > until) {
        ::kill(pid, SIGKILL);
        ::waitpid(pid, &status, 0);
        ADD_FAILURE() << "recruit sil did not end within " << seconds << " s";
        return -1;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    pid = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
  }
  ~Plant() {
    if (pid > 0) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, nullptr, 0);
    }
  }
  // The "listening on ..." line's endpoint, waiting at most 30 s for it.
  std::string Endpoint() {
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    const std::regex re("listening on (udp|pty) ([^ \n]+)");
    while (std::chrono::steady_clock::now() < until) {
      std::smatch m;
      const std::string text = ReadText(log);
      if (std::regex_search(text, m, re)) return m[2];
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return "";
  }
};

Plant StartPlant(const std::string& args, const std::string& name) {
  Plant p;
  p.log = Dir() / (name + ".log");
  const std::string cmd =
      "exec '" + kRecruit + "' sil " + args + " > '" + p.log.string() + "' 2>&1";
  p.pid = ::fork();
  if (p.pid == 0) {
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  return p;
}

// The task's double package built with the example controller, once per task.
std::string Controller(const std::string& task) {
  const fs::path pkg = Dir() / ("pkg_" + fs::path(task).filename().string());
  const fs::path bin = pkg / "sil_controller";
  if (fs::exists(bin)) return bin.string();
  const std::string cc = RECRUIT_HOST_CC;
  const std::string cmd =
      "'" + kRecruit + "' export --task '" + TaskFile(task) + "' --precision double --out '" +
      pkg.string() + "' > /dev/null && '" + cc +
      "' -std=c99 -O2 -ffp-contract=off -fno-math-errno -Wall -Wextra -Werror -I '" + pkg.string() +
      "' '" + RECRUIT_SOURCE_DIR + "/examples/sil/sil_controller.c' '" + pkg.string() +
      "/recruit_controller.c' -lm -o '" + bin.string() + "'";
  EXPECT_EQ(Shell(cmd), 0) << cmd;
  return bin.string();
}

nlohmann::json Simulate(const std::string& task, const std::string& opts, const std::string& name) {
  const fs::path out = Dir() / ("sim_" + name + ".json");
  const std::string cmd = "'" + kRecruit + "' simulate --task '" + TaskFile(task) + "' " + opts +
                          " --out '" + Dir().string() + "' --summary '" + out.string() +
                          "' --csv '" + (Dir() / (name + ".csv")).string() + "' > /dev/null";
  EXPECT_EQ(Shell(cmd), 0) << cmd;
  return nlohmann::json::parse(ReadText(out));
}

struct SilRun {
  int plant_rc = -1, controller_rc = -1;
  nlohmann::json summary;
  std::string log;
};

// One `recruit sil` run with the example controller; `link` "udp" or "pty".
SilRun RunSil(const std::string& task, const std::string& opts, const std::string& link,
              const std::string& faults, const std::string& name, double dT) {
  const fs::path summary = Dir() / ("sil_" + name + ".json");
  const fs::path pty = Dir() / ("pty_" + name);
  std::string args = "--task '" + TaskFile(task) + "' " + opts + " --summary '" + summary.string() +
                     "' --connect-timeout 20";
  if (link == "pty") args += " --link pty --pty-link '" + pty.string() + "'";
  const std::string ctl = Controller(task);
  Plant plant = StartPlant(args, name);
  const std::string endpoint = plant.Endpoint();
  SilRun r;
  EXPECT_FALSE(endpoint.empty()) << ReadText(plant.log);
  if (endpoint.empty()) return r;
  const std::string where = link == "udp" ? "--udp " + endpoint : "--pty '" + pty.string() + "'";
  r.controller_rc = Shell("timeout 60 '" + ctl + "' " + where + " --dT " + std::to_string(dT) +
                          " --timeout 10 " + faults);
  r.plant_rc = plant.Wait(60);
  r.log = ReadText(plant.log);
  if (r.plant_rc == 0) r.summary = nlohmann::json::parse(ReadText(summary));
  return r;
}

void ExpectSameMetrics(const nlohmann::json& a, const nlohmann::json& b, const std::string& what) {
  ASSERT_FALSE(a.is_null() || b.is_null()) << what;
  EXPECT_EQ(a["metrics"], b["metrics"]) << what;  // every metric, exactly
  EXPECT_EQ(a["control_instants"], b["control_instants"]) << what;
  EXPECT_EQ(a["bundles"], b["bundles"]) << what;
}

const std::string kArm = "--duration 20 --seed 3";

TEST(Sil, UdpRunEqualsSimulateAndCountsInjectedBadPackets) {
  const nlohmann::json ref = Simulate(kArmTask, kArm, "arm");
  const SilRun r =
      RunSil(kArmTask, kArm + " --speed max", "udp",
             "--corrupt 3 --truncate 4 --oversize 5 --replay 6 --junk 7", "udp_bad", 1);
  ASSERT_EQ(r.plant_rc, 0) << r.log;
  EXPECT_EQ(r.controller_rc, 0);
  ExpectSameMetrics(ref, r.summary, "arm_reach_hold_hand over udp");
  const nlohmann::json& s = r.summary["sil"];
  EXPECT_EQ(s["instants"], ref["control_instants"]);
  EXPECT_EQ(s["applied"], ref["control_instants"]);
  EXPECT_EQ(s["lost"], 0);
  EXPECT_EQ(s["late"], 0);
  EXPECT_EQ(s["replayed"], 1);
  EXPECT_EQ(s["malformed"], 2);  // the bit flip and the junk datagram
  EXPECT_EQ(s["truncated"], 1);
  EXPECT_EQ(s["oversized"], 1);
  EXPECT_EQ(s["unexpected"], 0);
}

TEST(Sil, ForceTaskOverUdpEqualsSimulate) {
  const std::string opts = "--duration 20 --seed 5";
  const nlohmann::json ref = Simulate(kStepsTask, opts, "iso");
  const double dT = ref["dT"].get<double>();
  const SilRun r = RunSil(kStepsTask, opts + " --speed 0", "udp", "", "udp_iso", dT);
  ASSERT_EQ(r.plant_rc, 0) << r.log;
  ExpectSameMetrics(ref, r.summary, "isometric_steps over udp");
  EXPECT_EQ(r.summary["sil"]["lost"], 0);
}

// A skipped answer and a late one: both instants lost (the plant held the previous command),
// the late answer counted and dropped.
TEST(Sil, LostAndLateAnswersAreCountedAndHeld) {
  const SilRun r = RunSil(kArmTask, kArm + " --speed max --deadline 1", "udp", "--skip 3 --late 7",
                          "udp_lost", 1);
  ASSERT_EQ(r.plant_rc, 0) << r.log;
  const nlohmann::json& s = r.summary["sil"];
  EXPECT_EQ(s["lost"], 2);
  EXPECT_EQ(s["late"], 1);
  EXPECT_EQ(s["applied"].get<int>(), s["instants"].get<int>() - 2);
  EXPECT_EQ(s["replayed"], 0);
  EXPECT_NE(r.log.find("2 lost"), std::string::npos) << r.log;
}

// The pseudo-terminal: a byte stream. A corrupted frame is dropped (and the bytes up to the next
// sync); a frame followed by junk is a good frame, so the oversized copy then makes the real
// answer a replay.
TEST(Sil, PtyRunEqualsSimulate) {
  const nlohmann::json ref = Simulate(kArmTask, kArm, "arm_pty");
  const SilRun r =
      RunSil(kArmTask, kArm + " --speed max", "pty", "--corrupt 3 --replay 6 --junk 7", "pty", 1);
  ASSERT_EQ(r.plant_rc, 0) << r.log;
  ExpectSameMetrics(ref, r.summary, "arm_reach_hold_hand over a pty");
  EXPECT_EQ(r.controller_rc, 0) << "the controller read the end frame";
  const nlohmann::json& s = r.summary["sil"];
  EXPECT_EQ(s["lost"], 0);
  EXPECT_EQ(s["replayed"], 1);
  EXPECT_GE(s["malformed"].get<int>(), 1);
  EXPECT_GE(s["junk_bytes"].get<int>(), 23);
  EXPECT_EQ(s["applied"], ref["control_instants"]);
  EXPECT_FALSE(fs::exists(Dir() / "pty_pty")) << "the link is removed at the end";
}

// Paced at 20x real time: 10 simulated s take at least 0.5 wall s, and the metrics still equal
// simulate's.
TEST(Sil, PacedRunTakesItsWallTime) {
  const std::string opts = "--duration 10 --seed 2";
  const nlohmann::json ref = Simulate(kArmTask, opts, "arm_paced");
  const auto t0 = std::chrono::steady_clock::now();
  const SilRun r = RunSil(kArmTask, opts + " --speed 20", "udp", "", "paced", 1);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(r.plant_rc, 0) << r.log;
  ExpectSameMetrics(ref, r.summary, "paced");
  EXPECT_GE(r.summary["wall_seconds"].get<double>(), 0.45);
  EXPECT_LT(wall, 30);
  EXPECT_EQ(r.summary["sil"]["speed"], 20.0);
}

TEST(Sil, NoControllerExitsSixWithinTheTimeout) {
  const auto t0 = std::chrono::steady_clock::now();
  Plant p = StartPlant("--task '" + TaskFile(kArmTask) +
                           "' --duration 5 --connect-timeout 0.5 --out '" + Dir().string() + "'",
                       "noctl");
  EXPECT_EQ(p.Wait(30), 6);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(wall, 20);
  EXPECT_NE(ReadText(p.log).find("no controller connected within"), std::string::npos)
      << ReadText(p.log);
}

TEST(Sil, ControllerWithAnotherPeriodIsRefused) {
  const SilRun r = RunSil(kArmTask, kArm + " --speed max", "udp", "", "wrong_dT", 0.5);
  EXPECT_EQ(r.plant_rc, 3) << r.log;
  EXPECT_EQ(r.controller_rc, 0) << "the end frame tells the controller";
  EXPECT_NE(r.log.find("export with the same --dT"), std::string::npos) << r.log;
}

// The shipped arm task's self-tuned loop runs in the plant's process only: refused, exit 3,
// naming it, before any controller is awaited.
TEST(Sil, SelfTunedTaskIsRefused) {
  const std::string log = (Dir() / "auto.log").string();
  EXPECT_EQ(Shell("'" + kRecruit + "' sil --task '" + TaskFile("models/tasks/arm_reach_hold") +
                  "' --duration 5 --connect-timeout 5 --out '" + Dir().string() + "' > '" + log +
                  "' 2>&1"),
            3);
  EXPECT_NE(ReadText(log).find("\"outer_loop\": \"auto\""), std::string::npos) << ReadText(log);
  // Refused before it listens for a firmware.
  EXPECT_EQ(ReadText(log).find("listening"), std::string::npos) << ReadText(log);
}

TEST(Sil, BadOptionsExitTwo) {
  const std::string base = "'" + kRecruit + "' sil --task '" + TaskFile(kArmTask) + "' ";
  EXPECT_EQ(Shell(base + "--speed fast 2>/dev/null"), 2);
  EXPECT_EQ(Shell(base + "--speed -1 2>/dev/null"), 2);
  EXPECT_EQ(Shell(base + "--link serial 2>/dev/null"), 2);
  EXPECT_EQ(Shell(base + "--bind 999.0.0.1 --connect-timeout 0.2 2>/dev/null"), 4);
}

}  // namespace file_sil_test
