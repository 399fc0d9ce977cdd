#include <iostream>

#include "cli/commands.h"

namespace recruit::cli {

// Placeholder until issue 5 lands: the subcommand exists so that --help lists it.
void AddRenderCommand(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("render", "(not built yet: issue 5)");
  cmd->callback([&exit_code] {
    std::cerr << "recruit render: not implemented yet (issue 5)\n";
    exit_code = 2;
  });
}

}  // namespace recruit::cli
