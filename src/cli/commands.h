// Each subcommand of `recruit` lives in its own file and registers itself on the app.
// A registration adds the subcommand, its options and a callback that returns the exit code
// through `exit_code`.
#pragma once

#include <CLI/CLI.hpp>

namespace recruit::cli {

void AddFilterCommand(CLI::App& app, int& exit_code);    // filter_command.cc
void AddIdentifyCommand(CLI::App& app, int& exit_code);  // identify_command.cc
void AddSimulateCommand(CLI::App& app, int& exit_code);  // simulate_command.cc
void AddSweepCommand(CLI::App& app, int& exit_code);     // sweep_command.cc
void AddTuneCommand(CLI::App& app, int& exit_code);      // tune_command.cc
void AddRenderCommand(CLI::App& app, int& exit_code);    // render_command.cc
void AddPlotCommand(CLI::App& app, int& exit_code);      // plot_command.cc
void AddTuneLoopCommand(CLI::App& app, int& exit_code);  // tune_loop_command.cc
void AddAttachCommand(CLI::App& app, int& exit_code);    // attach_command.cc
void AddExportCommand(CLI::App& app, int& exit_code);    // export_command.cc
void AddReplayCommand(CLI::App& app, int& exit_code);    // replay_command.cc
void AddSilCommand(CLI::App& app, int& exit_code);       // sil_command.cc

}  // namespace recruit::cli
