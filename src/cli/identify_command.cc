// recruit identify: fit the augmented transient model of an SMA unit (docs/identification.md)
// from the bench (switching the units through the plugin) or from a recorded switching log, and
// save it as a filter model file.
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli/commands.h"
#include "cli/errors.h"
#include "common/atomic_file.h"
#include "common/output_path.h"
#include "control/bench_recorder.h"
#include "control/excitation.h"
#include "control/identification.h"
#include "control/model_export.h"
#include "control/on_count_estimator.h"

namespace recruit::cli {
namespace {

struct IdentifyArgs {
  std::string bench = "models/isometric_bench.xml";
  std::string actuator;
  std::string log_in;
  int units = 60;
  double dT = 0.5;
  int states = 20;
  double duration = 900;
  double settle = 8;
  double holdout = 0.3;
  double smoothness = 1e-3;
  unsigned long long seed = 1;
  std::string output;
  std::string save_log;
};

int RunIdentify(const IdentifyArgs& a, const std::string& command_line) {
  using namespace recruit::control;
  if (a.states < 4 || a.states % 2 != 0) {
    return Fail("identify", "--states " + std::to_string(a.states) + ": must be even and >= 4",
                exit_code::kUsage);
  }
  SwitchingLog log;
  double unit_force = 0;
  nlohmann::json plant;  // the bench bundle (null for --log)
  std::string source;
  if (!a.log_in.empty()) {
    auto r = SwitchingLog::FromCsv(a.log_in, a.units);
    if (!r) {
      return Fail("identify", r.error());
    }
    log = std::move(r).value();
    source = a.log_in;
  } else {
    if (!(a.dT > 0) || !(a.duration > 0) || !(a.settle > 0)) {
      return Fail("identify", "--dt, --duration and --settle must be > 0", exit_code::kUsage);
    }
    const int total = static_cast<int>(a.duration / a.dT + 0.5);
    const int settle = std::max(2, static_cast<int>(a.settle / a.dT + 0.5));
    const Excitation e = MakeExcitation(settle, total, a.seed);
    std::cerr << "recruit identify: recording " << total << " instants (" << a.duration << " s) on "
              << a.bench << " at dT = " << a.dT << " s\n";
    auto r = RecordBench(a.bench, a.actuator, e, a.dT, a.seed);
    if (!r) {
      return Fail("identify", r.error());
    }
    log = std::move(r->log);
    unit_force = r->unit_force;
    plant = r->plant;
    source = a.bench;
  }
  if (!a.save_log.empty()) {
    if (Status s =
            CheckNotAnInput(a.save_log, "--save-log", {{"--log", a.log_in}, {"--bench", a.bench}});
        !s.ok()) {
      return Fail("identify", s.error(), exit_code::kUsage);
    }
    if (Status s = log.SaveCsv(a.save_log); !s) {
      return Fail("identify", s.error());
    }
  }
  FitOptions opt;
  opt.num_states = a.states;
  opt.holdout_fraction = a.holdout;
  opt.smoothness = a.smoothness;
  auto fit = IdentifyTransientModel(log, opt);
  if (!fit) {
    return Fail("identify", fit.error());
  }
  const TransientChain& c = fit->chain;
  const FilterModel model = ToFilterModel(c, log.num_units, log.dT, fit->force_noise_var);
  if (Status s = model.Validate("identified model"); !s) {
    return Fail("identify", s.error());
  }
  nlohmann::json j = model.ToJson();
  auto metrics = [](const FitMetrics& m) {
    return nlohmann::json{{"samples", m.samples}, {"rmse_N", m.rmse}, {"r2", m.r2}};
  };
  j["identification"] = {
      {"command", command_line},
      {"source", source},
      {"dT", log.dT},
      {"num_units", log.num_units},
      {"settled_unit_force_N", unit_force > 0 ? nlohmann::json(unit_force) : nlohmann::json()},
      {"heat_advance",
       std::vector<double>(c.heat_advance.data(), c.heat_advance.data() + c.heat_advance.size())},
      {"cool_advance",
       std::vector<double>(c.cool_advance.data(), c.cool_advance.data() + c.cool_advance.size())},
      {"train", metrics(fit->train)},
      {"holdout", metrics(fit->holdout)},
      {"two_state_holdout", metrics(fit->two_state_holdout)},
      {"R_N2", fit->force_noise_var}};
  if (!plant.is_null()) j["identification"]["plant"] = plant;
  const std::string out = a.output.empty() ? DefaultModelFile(log.dT, a.states) : a.output;
  if (Status s = CheckNotAnInput(out, "--output", {{"--log", a.log_in}, {"--bench", a.bench}});
      !s.ok()) {
    return Fail("identify", s.error(), exit_code::kUsage);
  }
  if (Status s = WriteFileAtomically(out, j.dump(2) + "\n"); !s) {
    return Fail("identify", s.error(), exit_code::kIo);
  }
  std::printf("identified %d-state model, N = %d, dT = %g s, from %s\n", c.num_states(),
              log.num_units, log.dT, source.c_str());
  std::printf("%-8s %-4s %10s %10s\n", "state", "on", "H (N)", "advance");
  const auto names = c.StateNames();
  const auto on = c.IsOn();
  for (int s = 0; s < c.num_states(); ++s) {
    double adv = 1.0;
    bool has_adv = false;
    if (s >= c.heat(1) && s <= c.heat(c.chain_length)) {
      adv = c.heat_advance[s - c.heat(1)];
      has_adv = true;
    } else if (s >= c.cool(1)) {
      adv = c.cool_advance[s - c.cool(1)];
      has_adv = true;
    }
    if (has_adv) {
      std::printf("%-8s %-4s %10.4f %10.3f\n", names[s].c_str(), on[s] ? "on" : "off", c.force[s],
                  adv);
    } else {
      std::printf("%-8s %-4s %10.4f %10s\n", names[s].c_str(), on[s] ? "on" : "off", c.force[s],
                  "-");
    }
  }
  if (unit_force > 0) std::printf("settled unit force (plugin): %.4f N\n", unit_force);
  std::printf("train:   %d samples, RMSE %.3f N, R^2 %.4f\n", fit->train.samples, fit->train.rmse,
              fit->train.r2);
  std::printf(
      "holdout: %d samples, RMSE %.3f N, R^2 %.4f (two-state model: RMSE %.3f N, "
      "R^2 %.4f)\n",
      fit->holdout.samples, fit->holdout.rmse, fit->holdout.r2, fit->two_state_holdout.rmse,
      fit->two_state_holdout.r2);
  std::printf("R = %.4g N^2 (sd %.3f N)\nwrote %s\n", fit->force_noise_var,
              std::sqrt(fit->force_noise_var), out.c_str());
  return 0;
}

}  // namespace

void AddIdentifyCommand(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<IdentifyArgs>();
  auto* cmd = app.add_subcommand(
      "identify",
      "Fit the augmented transient model of an SMA unit (heating/cooling chains, per-state "
      "force, advance probabilities) by least squares, from the bench or a switching log, and "
      "save it as a filter model file");
  cmd->add_option("--bench", args->bench, "MJCF bench model with an SMA bundle")
      ->capture_default_str();
  cmd->add_option("--actuator", args->actuator, "bundle's actuator name (default: the first)");
  cmd->add_option("--log", args->log_in,
                  "fit a recorded CSV log (columns time,p_on,p_off,force at the control "
                  "instants) instead of running the bench")
      ->check(CLI::ExistingFile);
  cmd->add_option("--units", args->units, "units in the bundle of a --log")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000000));
  cmd->add_option("--dt", args->dT, "sampling period dT, s (bench), > 0")
      ->check(Positive())
      ->capture_default_str();
  cmd->add_option("--states", args->states, "model states m (even, >= 4)")->capture_default_str();
  cmd->add_option("--duration", args->duration, "bench experiment length, s, > 0")
      ->check(Positive())
      ->capture_default_str();
  cmd->add_option("--settle", args->settle, "hold time for a unit to settle, s, > 0")
      ->check(Positive())
      ->capture_default_str();
  cmd->add_option("--holdout", args->holdout, "fraction of the log held out (its end)")
      ->capture_default_str()
      ->check(NumberIn(0, false, 0.9, "in [0, 0.9]"));
  cmd->add_option("--smoothness", args->smoothness,
                  "weight of the neighbour-difference penalty on H (relative), >= 0")
      ->check(NonNegative())
      ->capture_default_str();
  cmd->add_option("--seed", args->seed, "seed of the excitation and the bench")
      ->capture_default_str();
  cmd->add_option("-o,--output", args->output,
                  "model file to write (default models/identified/bench_n60_dt<dT>_m<m>.json)");
  cmd->add_option("--save-log", args->save_log, "also write the bench's switching log (CSV)");
  cmd->callback([args, &exit_code, cmd] {
    std::string line = "recruit identify";
    for (const auto* opt : cmd->get_options()) {
      if (opt->count() > 0 && !opt->get_lnames().empty()) {
        for (const auto& r : opt->results()) line += " --" + opt->get_lnames()[0] + " " + r;
      }
    }
    exit_code = RunIdentify(*args, line);
  });
}

}  // namespace recruit::cli
