#include "cli/run_options.h"

#include "cli/errors.h"

namespace recruit::cli {

void AddRunOptions(CLI::App* cmd, sim::RunOptions* options) {
  // The commands identify a missing filter model (and cache it), as docs/identification.md says.
  options->identify_missing_models = true;
  cmd->add_option_function<std::string>(
         "--estimator", [options](const std::string& v) { options->estimator = v; },
         "How the controller counts units that are on: output (force / settled unit force, the "
         "paper's output-only count), kalman2 (population Kalman filter, two-state model), "
         "kalman-augmented (population Kalman filter on the identified 20-state model, "
         "models/identified/) [default: the task file's]")
      ->type_name("NAME");
  cmd->add_option_function<std::string>(
         "--filter-model", [options](const std::string& v) { options->filter_model = v; },
         "Filter model file (JSON) for kalman-augmented [default: the task file's, else the "
         "one identified for dT]")
      ->type_name("FILE")
      ->check(CLI::ExistingFile);
  cmd->add_option_function<double>(
         "--dT", [options](double v) { options->dT = v; },
         "Controller sampling period, s, in (0, 1000] [default: the task file's]")
      ->type_name("SECONDS")
      ->check(SamplingPeriod());
  cmd->add_option_function<double>(
         "--lambda", [options](double v) { options->lambda = v; },
         "Gain of the expectation law, in (0, 1] [default: the task file's]")
      ->type_name("GAIN")
      ->check(Fraction());
  cmd->add_option_function<double>(
         "--force-noise-std", [options](double v) { options->force_noise_std = v; },
         "Kalman estimators: force measurement noise std, N (0 = the estimator's default) "
         "[default: the task file's]")
      ->type_name("N")
      ->check(NonNegative());
  cmd->add_option("--seed", options->seed, "Seed of the units' random draws")
      ->capture_default_str();
  cmd->add_option_function<double>(
         "--duration", [options](double v) { options->duration = v; },
         "Simulated time, s (> 0) [default: the task file's]")
      ->type_name("SECONDS")
      ->check(Positive());
  cmd->add_flag("--progress", options->progress,
                "Show progress on stderr even when it is not a terminal");
}

}  // namespace recruit::cli
