#include <iostream>

#include "cli/commands.h"

namespace recruit::cli {

// Placeholder until issue 4 lands: the subcommand exists so that --help lists it.
void AddSweepCommand(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("sweep", "(not built yet: issue 4)");
  cmd->callback([&exit_code] {
    std::cerr << "recruit sweep: not implemented yet (issue 4)\n";
    exit_code = 2;
  });
}

}  // namespace recruit::cli
