// recruit: command-line front end. Subcommands are registered from their own files.
#include <iostream>

#include "cli/commands.h"

int main(int argc, char** argv) {
  CLI::App app{
      "Recruit: stochastic recruitment control of SMA muscle bundles in MuJoCo, with the "
      "population Kalman filter of Odhner and Asada (ACC 2010)."};
  app.require_subcommand(1);
  int exit_code = 0;
  recruit::cli::AddFilterCommand(app, exit_code);
  recruit::cli::AddIdentifyCommand(app, exit_code);
  recruit::cli::AddSimulateCommand(app, exit_code);
  recruit::cli::AddSweepCommand(app, exit_code);
  recruit::cli::AddRenderCommand(app, exit_code);
  recruit::cli::AddPlotCommand(app, exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  return exit_code;
}
