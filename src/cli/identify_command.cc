// recruit identify: fit the augmented transient model of an SMA unit (docs/identification.md)
// from the bench (switching the units through the plugin) or from a recorded switching log, and
// save it as a filter model file.
#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli/commands.h"
#include "cli/errors.h"
#include "common/atomic_file.h"
#include "common/output_path.h"
#include "control/on_count_estimator.h"
#include "control/sampling_period.h"
#include "identification/bench_recorder.h"
#include "identification/excitation.h"
#include "identification/identification.h"
#include "identification/model_cache.h"
#include "identification/model_export.h"
#include "identification/plant_identification.h"

namespace recruit::cli {
namespace {

struct IdentifyArgs {
  std::string bench = "models/isometric_bench.xml";
  std::string actuator;
  std::string log_in;
  int units = 60;
  double dT = control::kDefaultDT;  // --bench; a --log's is read from its time column
  int states = 20;
  double duration = 900;
  double settle = 8;
  double holdout = 0.3;
  double smoothness = 1e-3;
  unsigned long long seed = 1;
  std::string output;
  std::string save_log;
};

// The model as written, one line per state: its name and H from the model file's JSON (H as the
// shortest text that reads back as the written double, so the table is the file's H exactly:
// clamped to >= 0 and, from the bench, carried onto the force law), on/off and the advance
// probability from the fitted chain.
void PrintModel(const recruit::identification::TransientChain& c, const nlohmann::json& model) {
  const nlohmann::json& names = model.at("states");
  const nlohmann::json& H = model.at("H").at(0);
  std::printf("%-8s %-4s %24s %10s\n", "state", "on", "H (N)", "advance");
  const auto on = c.IsOn();
  for (int s = 0; s < c.num_states(); ++s) {
    char adv[32] = "-";
    if (s >= c.heat(1) && s <= c.heat(c.chain_length)) {
      std::snprintf(adv, sizeof adv, "%.3f", c.heat_advance[s - c.heat(1)]);
    } else if (s >= c.cool(1)) {
      std::snprintf(adv, sizeof adv, "%.3f", c.cool_advance[s - c.cool(1)]);
    }
    const std::string h = fmt::format("{}", H.at(s).get<double>());
    std::printf("%-8s %-4s %24s %10s\n", names.at(s).get<std::string>().c_str(),
                on[s] ? "on" : "off", h.c_str(), adv);
  }
}

void PrintFit(const recruit::identification::IdentificationResult& fit) {
  std::printf("train:   %d samples, RMSE %.3f N, R^2 %.4f\n", fit.train.samples, fit.train.rmse,
              fit.train.r2);
  std::printf(
      "holdout: %d samples, RMSE %.3f N, R^2 %.4f (two-state model: RMSE %.3f N, "
      "R^2 %.4f)\n",
      fit.holdout.samples, fit.holdout.rmse, fit.holdout.r2, fit.two_state_holdout.rmse,
      fit.two_state_holdout.r2);
  std::printf(
      "R = %.4g N^2 + n %.4g N^2 + n^2 %.4g N^2, n units in transit (constant R: %.4g N^2)\n",
      fit.noise.r0, fit.noise.r_transit, fit.noise.r_transit2, fit.force_noise_var);
}

// --log: the chain fitted to a recorded switching log (plant unknown: no length model).
Result<nlohmann::json> IdentifyFromLog(const IdentifyArgs& a, const std::string& command_line) {
  using namespace recruit::control;
  using namespace recruit::identification;
  auto log = SwitchingLog::FromCsv(a.log_in, a.units, a.actuator);
  if (!log) return Error{log.error(), log.code()};
  FitOptions opt;
  opt.num_states = a.states;
  opt.holdout_fraction = a.holdout;
  opt.smoothness = a.smoothness;
  auto fit = IdentifyTransientModel(*log, opt);
  if (!fit) return Error{fit.error(), fit.code()};
  // Forces below zero (a few hundredths of a newton in the cooling tail) are none: H >= 0. With
  // the plant unknown, no force law carries H to other lengths (that needs --bench).
  TransientChain c = fit->chain;
  c.force = c.force.cwiseMax(0.0);
  const estimation::FilterModel model = ToFilterModel(c, log->num_units, log->dT, fit->noise.r0,
                                                      fit->noise.r_transit, fit->noise.r_transit2);
  if (Status s = model.Validate("identified model"); !s) return Error{s.error(), s.code()};
  nlohmann::json j = model.ToJson();
  j["identification"] = {{"command", command_line},
                         {"source", a.log_in},
                         {"dT", log->dT},
                         {"num_units", log->num_units},
                         {"train", MetricsJson(fit->train)},
                         {"holdout", MetricsJson(fit->holdout)},
                         {"two_state_holdout", MetricsJson(fit->two_state_holdout)},
                         {"R_N2", fit->noise.r0},
                         {"R_transit_N2", fit->noise.r_transit},
                         {"R_transit2_N2", fit->noise.r_transit2},
                         {"R_constant_N2", fit->force_noise_var}};
  std::printf("identified %d-state model, N = %d, dT = %g s, from %s\n", c.num_states(),
              log->num_units, log->dT, a.log_in.c_str());
  PrintModel(c, j);
  PrintFit(*fit);
  return j;
}

// --bench: the shared pipeline on the MuJoCo plant (identification/plant_identification.h).
Result<nlohmann::json> IdentifyFromBench(const IdentifyArgs& a, const std::string& command_line) {
  using namespace recruit::control;
  using namespace recruit::identification;
  PlantIdentificationOptions o;
  o.dT = a.dT;
  o.num_states = a.states;
  o.duration = a.duration;
  o.settle = a.settle;
  o.holdout = a.holdout;
  o.smoothness = a.smoothness;
  o.seed = a.seed;
  std::cerr << "recruit identify: recording " << a.duration << " s on " << a.bench
            << " at dT = " << a.dT << " s, then checks at other tendon lengths\n";
  auto id = IdentifyOnPlant(a.bench, a.actuator, o, command_line);
  if (!id) return Error{id.error(), id.code()};
  if (!a.save_log.empty()) {
    if (Status s = CheckNotAnInput(a.save_log, "--save-log", {{"--bench", a.bench}}); !s.ok()) {
      return Error{s.error(), s.code()};
    }
    if (Status s = id->log.SaveCsv(a.save_log); !s) return Error{s.error(), s.code()};
  }
  const nlohmann::json& ident = id->model["identification"];
  std::printf("identified %d-state model, N = %d, dT = %g s, on %s %s (held at %s)\n",
              id->fit.chain.num_states(), ident["num_units"].get<int>(), a.dT, a.bench.c_str(),
              ident["plant"].value("actuator", std::string()).c_str(),
              ident["pose"].get<std::string>().empty() ? "its fixed pose"
                                                       : ident["pose"].get<std::string>().c_str());
  PrintModel(id->fit.chain, id->model);
  std::printf("settled unit force (plugin, at ref_length): %.4f N\n",
              ident["settled_unit_force_N"].get<double>());
  PrintFit(id->fit);
  for (const LengthCheck& c : id->checks) {
    std::printf("check at %s (tendon %.4f m): %d samples, RMSE %.3f N, R^2 %.4f\n", c.pose.c_str(),
                c.tendon_length, c.fit.samples, c.fit.rmse, c.fit.r2);
  }
  return id->model;
}

int RunIdentify(const IdentifyArgs& a, const std::string& command_line) {
  using namespace recruit::control;
  using namespace recruit::identification;
  if (a.states < 4 || a.states % 2 != 0) {
    return Fail("identify", "--states " + std::to_string(a.states) + ": must be even and >= 4",
                exit_code::kUsage);
  }
  auto refused = [&a](const std::string& out) {
    return CheckNotAnInput(out, "--output", {{"--log", a.log_in}, {"--bench", a.bench}});
  };
  if (!a.output.empty()) {
    if (Status s = refused(a.output); !s.ok())
      return Fail("identify", s.error(), exit_code::kUsage);
  }
  auto j = a.log_in.empty() ? IdentifyFromBench(a, command_line) : IdentifyFromLog(a, command_line);
  if (!j) return Fail("identify", j.failure());
  std::string out = a.output;
  if (out.empty() && !a.log_in.empty()) {
    // Named by the log's dT, read from its time column.
    out = DefaultModelFile((*j)["identification"]["dT"].get<double>(), a.states);
    if (Status s = refused(out); !s.ok()) return Fail("identify", s.error(), exit_code::kUsage);
  }
  if (out.empty()) {
    // The model cache, where simulate and sweep look for it (identification/model_cache.h).
    const auto& plant = (*j)["identification"]["plant"];
    out = ModelSearchPath().back() + "/" + ModelFileName(plant, a.dT, a.states);
    std::error_code ec;
    std::filesystem::create_directories(ModelSearchPath().back(), ec);
  }
  if (Status s = WriteFileAtomically(out, j->dump(2) + "\n"); !s) {
    return Fail("identify", s.error(), exit_code::kIo);
  }
  std::printf("wrote %s\n", out.c_str());
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
  cmd->add_option(
      "--actuator", args->actuator,
      "bundle's actuator name (default: the first; with --log: a bench log's only one)");
  cmd->add_option("--log", args->log_in,
                  "fit a recorded CSV log instead of running the bench: a bench log "
                  "(docs/formats/bench_log.md; its bundle by --actuator) or the columns "
                  "time,p_on,p_off,force at the control instants")
      ->check(CLI::ExistingFile);
  cmd->add_option("--units", args->units, "units in the bundle of a --log")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000000));
  cmd->add_option("--dt", args->dT,
                  "sampling period dT, s, of the bench's recording; the default is the "
                  "controller's, as in simulate and task files (a --log's is read from its "
                  "time column)")
      ->check(SamplingPeriod())
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
  cmd->add_option(
      "-o,--output", args->output,
      "model file to write (default for --bench: the model cache, where simulate finds it; "
      "for --log: models/identified/bench_n60_dt<dT>_m<m>.json)");
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
