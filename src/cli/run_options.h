// Options shared by `recruit simulate` and `recruit render`: the estimator, dT, lambda, seed and
// duration of one closed-loop run (recruit::sim::RunOptions).
#pragma once

#include <CLI/CLI.hpp>

#include "sim/run_task.h"

namespace recruit::cli {

// Adds --estimator, --filter-model, --dT, --lambda, --seed, --duration and --progress to `cmd`,
// writing into `options` (unset options keep the task file's values).
// Also turns on identify_missing_models: the commands identify a missing filter model.
void AddRunOptions(CLI::App* cmd, sim::RunOptions* options);

}  // namespace recruit::cli
