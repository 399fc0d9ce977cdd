// recruit: command-line front end. Subcommands are registered from their own files. One error
// policy for all of them (cli/errors.h, docs/reliability.md): exit 0 ok, 2 usage, 3 bad input,
// 4 I/O, 5 internal; temporary files are removed on SIGINT/SIGTERM.
#include <mujoco/mujoco.h>

#include <exception>
#include <iostream>
#include <new>
#include <sstream>
#include <string>

#include "cli/commands.h"
#include "cli/errors.h"
#include "common/atomic_file.h"
#include "common/data_path.h"
#include "common/mujoco_warnings.h"
#include "common/version.h"

namespace {

// `recruit --version`: this build's version and the MuJoCo it was compiled against (its header)
// and runs with (the libmujoco loaded). mjVERSION_HEADER is major * 1e6 + minor * 1e3 + patch.
std::string VersionText() {
  const int h = mjVERSION_HEADER;
  std::ostringstream s;
  s << "recruit " << recruit::ProjectVersion() << " (" << recruit::CodeVersion() << ")\n"
    << "MuJoCo built against " << h / 1000000 << "." << h / 1000 % 1000 << "." << h % 1000
    << " (mjVERSION_HEADER " << h << "), running " << mj_versionString();
  return s.str();
}

}  // namespace

int main(int argc, char** argv) {
  using namespace recruit;
  InstallTempFileCleanupOnSignals();
  InstallMujocoWarnings();               // stderr, once each, no MUJOCO_LOG.TXT
  SetDataDir(RECRUIT_DATA_DIR_DEFAULT);  // models/identified/ of the tree it was built from
  CLI::App app{
      "Recruit: stochastic recruitment control of SMA muscle bundles in MuJoCo, with the "
      "population Kalman filter of Odhner and Asada (ACC 2010).\n"
      "Exit codes (all commands): 0 ok, 2 usage (bad option or value), 3 bad input file content, "
      "4 I/O (cannot read or write), 5 internal error. See docs/reliability.md."};
  app.require_subcommand(1);
  app.set_version_flag("--version", VersionText,
                       "Print the version of recruit and MuJoCo and exit");
  int exit_code = 0;
  // When the first argument names a command, only that one is built: building all six, with
  // their options and validators, was ~3 % of the CPU of a short run's start.
  const struct {
    const char* name;
    void (*add)(CLI::App&, int&);
  } commands[] = {{"filter", cli::AddFilterCommand},
                  {"identify", cli::AddIdentifyCommand},
                  {"simulate", cli::AddSimulateCommand},
                  {"sweep", cli::AddSweepCommand},
                  {"render", cli::AddRenderCommand},
                  {"plot", cli::AddPlotCommand},
                  {"tune-loop", cli::AddTuneLoopCommand},
                  {"attach", cli::AddAttachCommand},
                  {"export", cli::AddExportCommand},
                  {"replay", cli::AddReplayCommand},
                  {"sil", cli::AddSilCommand},
                  {"tune", cli::AddTuneCommand}};
  const std::string first = argc > 1 ? argv[1] : "";
  bool named = false;
  for (const auto& c : commands) named |= first == c.name;
  for (const auto& c : commands) {
    if (!named || first == c.name) c.add(app, exit_code);
  }
  if (argc == 1) {  // no command: the help, not an error
    app.name("recruit");
    std::cout << app.help();
    return 0;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::string where = "recruit";
    for (const auto* sub : app.get_subcommands()) where += " " + sub->get_name();
    // Paths stay readable (200 characters); a 2 MB value does not come back whole.
    std::cerr << where << ": " << ShortenLongTokens(e.what(), 200) << "\nRun with --help for more "
              << "information.\n";
    return exit_code::kUsage;
  } catch (const std::bad_alloc&) {
    std::cerr << "recruit: out of memory\n";
    return exit_code::kInternal;
  } catch (const std::exception& e) {
    std::cerr << "recruit: internal error (please report it): " << ShortenLongTokens(e.what())
              << "\n";
    return exit_code::kInternal;
  }
  return exit_code;
}
