#include <iostream>

#include "cli/commands.h"

namespace recruit::cli {

// Placeholder until issue 2 lands: the subcommand exists so that --help lists it.
void AddFilterCommand(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("filter", "(not built yet: issue 2)");
  cmd->callback([&exit_code] {
    std::cerr << "recruit filter: not implemented yet (issue 2)\n";
    exit_code = 2;
  });
}

}  // namespace recruit::cli
