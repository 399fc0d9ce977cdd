// `recruit filter`: runs one estimator offline over a recorded log (docs/formats/filter.md).
#include <filesystem>
#include <iostream>
#include <string>
#include <system_error>
#include <utility>

#include "cli/commands.h"
#include "common/atomic_file.h"
#include "common/short_text.h"
#include "estimation/count_filter.h"
#include "estimation/filter_log.h"
#include "estimation/filter_model.h"
#include "estimation/json_matrix.h"
#include "identification/plant_record.h"

namespace recruit::cli {
namespace {

struct FilterArgs {
  std::string model, log, out;
  std::string plant, actuator;  // the MJCF and bundle the log was recorded on (optional)
  estimation::CountFilterOptions options;
};

// The output is written through a temporary file renamed onto --out, which would replace an
// input given under the same name, another path or a link to it: refused before anything runs.
Status CheckOutputIsNoInput(const std::string& out, const FilterArgs& a) {
  for (const auto& [option, input] : {std::pair{"--log", a.log}, std::pair{"--model", a.model}}) {
    std::error_code ec;
    if (out == input || std::filesystem::equivalent(out, input, ec)) {
      return Error{"--out '" + ShortText(out) + "' is the same file as " + option + " '" +
                       ShortText(input) + "'; refusing to overwrite an input",
                   ErrorCode::kUsage};
    }
  }
  return Status::Ok();
}

int RunFilter(const FilterArgs& a) {
  auto fail = [](const Error& e) { return Fail("filter", e); };
  if (Status s = CheckOutputIsNoInput(a.out, a); !s.ok()) return fail(s.failure());
  auto model = estimation::FilterModel::FromJson(a.model);
  if (!model.ok()) return fail(model.failure());
  // A model identified on another plant than the log's is refused (its H and chain describe
  // other units), as simulate and sweep refuse it.
  if (!a.plant.empty()) {
    auto record = identification::PlantRecordOf(a.plant, a.actuator);
    if (!record.ok()) return fail(record.failure().In("--plant: "));
    if (Status s = control::CheckModelPlant(a.model, *record); !s.ok()) return fail(s.failure());
  }
  auto filter = estimation::MakeCountFilter(*model, a.options);
  if (!filter.ok()) return fail(filter.failure());
  // Streamed: the log is read, stepped and written row by row (memory flat in its length).
  auto log = estimation::FilterLogReader::OpenFile(a.log, *model, a.actuator);
  if (!log.ok()) return fail(log.failure());
  AtomicFile out(a.out, std::ios::out | std::ios::binary);
  if (!out.ok()) return fail(out.failure());
  if (Status s = estimation::RunFilterStream(*model, **log, **filter, out.stream()); !s.ok()) {
    return fail(s.failure());  // AtomicFile removes its temporary file: nothing is written
  }
  if (Status s = out.Commit(); !s.ok()) return fail(s.failure());
  return 0;
}

}  // namespace

void AddFilterCommand(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<FilterArgs>();
  auto* cmd = app.add_subcommand(
      "filter",
      "Run a population estimator offline over a recorded log: the Kalman filter for population "
      "Markov chains (extended, conservative or plain covariance), the exact Bayesian filter or "
      "a particle filter. Formats: docs/formats/filter.md.");
  cmd->add_option("--model", args->model,
                  "Filter model file (JSON): states, N, H, R, optional G and Qw, the transition "
                  "(broadcast, explicit or constant) and the initial belief")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--log", args->log,
                  "Log (CSV): optional t, the inputs of each step (p_on,p_off or A_i_j) and the "
                  "measurement (y, or y_0..y_{r-1}; empty cells = no measurement that step); or "
                  "a bench log (docs/formats/bench_log.md), its bundle by --actuator")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", args->out,
                  "Output CSV: step[,t],updated,x_<state>...,var_<state>... (estimate and "
                  "diagonal of its covariance per step), written atomically")
      ->required();
  cmd->add_option("--plant", args->plant,
                  "MJCF model the log was recorded on: the model file must have been identified "
                  "on that plant's bundle (its identification.plant), else it is refused")
      ->check(CLI::ExistingFile);
  cmd->add_option(
      "--actuator", args->actuator,
      "--plant's bundle (default: its first), and a bench log's (default: its only one)");
  cmd->add_option("--estimator", args->options.estimator,
                  std::string("Estimator: ") + estimation::kEstimatorNames)
      ->check(CLI::IsMember({"extended", "conservative", "plain", "exact", "particle"}))
      ->capture_default_str();
  cmd->add_option("--particles", args->options.particles, "Particle filter: number of particles")
      ->check(CLI::Range(1, 100000000))
      ->capture_default_str();
  cmd->add_option("--seed", args->options.seed, "Particle filter: random seed")
      ->capture_default_str();
  cmd->add_option("--max-states", args->options.max_states,
                  "Exact filter: refuse models with more count vectors C(N+m-1, m-1) than this")
      ->check(CLI::Range(uint64_t{1}, uint64_t{200000000}))
      ->capture_default_str();
  cmd->callback([args, &exit_code] { exit_code = RunFilter(*args); });
}

}  // namespace recruit::cli
