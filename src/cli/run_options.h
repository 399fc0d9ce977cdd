// Options shared by `recruit simulate` and `recruit render`: the estimator, dT, lambda, seed and
// duration of one closed-loop run (recruit::sim::RunOptions).
#pragma once

#include <CLI/CLI.hpp>

#include "sim/run_task.h"

namespace recruit::cli {

// Adds --estimator, --filter-model, --dT, --lambda, --seed, --duration and --progress to `cmd`,
// writing into `options` (unset options keep the task file's values).
void AddRunOptions(CLI::App* cmd, sim::RunOptions* options);

}  // namespace recruit::cli
