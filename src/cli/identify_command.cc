#include <iostream>

#include "cli/commands.h"

namespace recruit::cli {

// Placeholder until issue 4 lands: the subcommand exists so that --help lists it.
void AddIdentifyCommand(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("identify", "(not built yet: issue 4)");
  cmd->callback([&exit_code] {
    std::cerr << "recruit identify: not implemented yet (issue 4)\n";
    exit_code = 2;
  });
}

}  // namespace recruit::cli
