// dualgrid: SUMO traffic -> radar detections -> dynamic occupancy grid, scored against truth.
#include <unistd.h>

#include <cerrno>
#include <csignal>

#include <filesystem>
#include <iostream>
#include <new>
#include <stdexcept>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cli_options.hpp"
#include "dualgrid/core/input_file.hpp"
#include "dualgrid/scenario/loader.hpp"
#include "dualgrid/sim/sumo_simulation.hpp"
#include "exit_codes.hpp"
#include "signals.hpp"

namespace {

using namespace dualgrid::tools;

constexpr const char* kExitCodes =
    "Exit codes: 0 done; 1 the run failed (SUMO error, an output not written); 2 bad input "
    "(command line, scenario or network file; nothing simulated); 3 experiment: some seed runs "
    "failed (the others are aggregated), regress: a case did not run, sweep/collect: runs are "
    "missing; regress: 1 a check failed; "
    "130/143 stopped by SIGINT/SIGTERM (results of the "
    "simulated part written, marked incomplete). Details: docs/cli.md.";

// --version: the version and where the program found its data (installed tree or build tree).
std::string VersionText(const dualgrid::sim::NetworkDirLocation& data) {
  return std::string("dualgrid ") + DUALGRID_VERSION + "\nnetworks: " + data.dir.string() + " (" +
         data.source + ")";
}

// A std::filesystem error as "PATH: WHAT FAILED: WHY" (the library's text reads
// "filesystem error: cannot get file size: Is a directory [PATH]").
std::string FilesystemMessage(const std::filesystem::filesystem_error& e) {
  std::string op = e.what();
  const std::string prefix = "filesystem error: ";
  if (op.rfind(prefix, 0) == 0) op.erase(0, prefix.size());
  op = op.substr(0, op.find(": "));  // "cannot get file size"
  std::string where = e.path1().string();
  if (!e.path2().empty()) where += (where.empty() ? "" : " -> ") + e.path2().string();
  return (where.empty() ? "" : where + ": ") + op + ": " + e.code().message();
}

// The command the user ran: the launcher `dualgrid` names itself in DUALGRID_COMMAND before it
// executes this program (tools/launcher/launcher.cpp); run directly, this program itself. Child
// runs start it, and the installed data are found from it (PREFIX/bin/dualgrid -> PREFIX/share).
std::string CommandPath(const char* argv0) {
  if (const char* command = std::getenv("DUALGRID_COMMAND"); command && *command) return command;
  char buf[4096];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  return n > 0 ? std::string(buf, n) : std::string(argv0);
}

std::string OneLine(std::string s) {
  for (char& c : s)
    if (c == '\n') c = ' ';
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

// The subcommand being parsed when the error happened, for the "see --help" hint.
std::string HelpHint(const CLI::App& app) {
  for (const CLI::App* sub : app.get_subcommands())
    return "dualgrid " + sub->get_name() + " --help";
  return "dualgrid --help";
}

}  // namespace

// OpenMP threads that spin while they wait (libgomp's default: ~3 ms) steal the time slices of
// the threads doing the work when another process is busy on the cores: measured with two other
// CPU-bound processes on 2 cores, a paper-size filter cycle took 14 ms on 2 threads instead of
// 2.5 ms with passive waiting (docs/performance.md). Purely passive waiting (a futex sleep at
// every barrier) costs ~30 us per barrier on a quiet machine, though; a spin of ~3 us
// (GOMP_SPINCOUNT=300) before sleeping keeps most of the quiet speed and the robustness under
// load. libgomp reads these variables when it is loaded, before main: the launcher `dualgrid`
// sets them before it executes this program (tools/launcher/launcher.cpp). Run directly without
// them, the program re-executes itself once with them set (loading every library twice), unless the
// user chose a policy or spin count. Returns only if no re-exec happened.
static void UseShortOpenMpSpinning(char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") != nullptr || std::getenv("GOMP_SPINCOUNT") != nullptr) return;
  if (setenv("OMP_WAIT_POLICY", "PASSIVE", 1) != 0 || setenv("GOMP_SPINCOUNT", "300", 1) != 0)
    return;
  execv("/proc/self/exe", argv);
  // exec failed (no /proc): run on with the default policy; the variables still reach children.
}

int main(int argc, char** argv) {
  UseShortOpenMpSpinning(argv);
  // Past a file-size limit (ulimit -f) a write should fail and be reported naming the file, not
  // kill the process with SIGXFSZ and leave a half-written run behind silently.
  std::signal(SIGXFSZ, SIG_IGN);
  InstallStopHandlers();
  CLI::App app{
      "dualgrid: radar-only dynamic occupancy grid with dual particle weights, "
      "co-simulated with SUMO.\nScenarios are YAML files (see scenarios/ and "
      "docs/scenarios.md)."};
  app.require_subcommand(1);
  app.footer(kExitCodes);
  const std::string command = CommandPath(argv[0]);
  const dualgrid::sim::NetworkDirLocation data = dualgrid::sim::FindNetworkDir(command);
  app.set_version_flag("--version", VersionText(data));
  const CliContext ctx{data.dir, command};
  const std::vector<Command> commands = {
      AddSimCommand(app, ctx),     AddSnapshotCommand(app, ctx),   AddRunCommand(app, ctx),
      AddReplayCommand(app, ctx),  AddExperimentCommand(app, ctx), AddTangentialCommand(app, ctx),
      AddRegressCommand(app, ctx), AddSweepCommand(app, ctx),      AddCollectCommand(app, ctx),
      AddFilterCommand(app, ctx),  AddExportCommand(app, ctx)};

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    // A first word that is no subcommand: CLI11 would only say that one is required.
    if (app.get_subcommands().empty() && argc > 1 && argv[1][0] != '-') {
      std::string names;
      for (const Command& c : commands) names += (names.empty() ? "" : ", ") + c.app->get_name();
      std::cerr << "dualgrid: error: unknown command '" << OneLine(argv[1]) << "' (expected one of "
                << names << "; see dualgrid --help)\n";
      return kExitBadInput;
    }
    std::cerr << "dualgrid: error: " << OneLine(e.what()) << " (see " << HelpHint(app) << ")\n";
    return kExitBadInput;
  }
  try {
    for (const Command& c : commands)
      if (c.app->parsed()) return c.run();
  } catch (const dualgrid::InputStopped& e) {
    std::cerr << "dualgrid: " << OneLine(e.what()) << "\n";
    return StopExitCode();
  } catch (const dualgrid::scenario::ConfigError& e) {
    std::cerr << "dualgrid: error: " << OneLine(e.what()) << "\n";
    return kExitBadInput;
  } catch (const std::invalid_argument& e) {
    std::cerr << "dualgrid: error: " << OneLine(e.what()) << "\n";
    return kExitBadInput;
  } catch (const std::bad_alloc&) {
    std::cerr << "dualgrid: error: out of memory (an input asks for more than this machine has; "
                 "the limits of each input: docs/cli.md)\n";
    return kExitRunFailed;
  } catch (const std::filesystem::filesystem_error& e) {
    std::cerr << "dualgrid: error: " << OneLine(FilesystemMessage(e)) << "\n";
    // A path that cannot name a file at all (a symbolic link loop, a name too long) is bad input
    // wherever it is met; anything else (a full disk, an --out under a file) is not.
    const bool system = e.code().category() == std::generic_category() ||
                        e.code().category() == std::system_category();
    if (system && (e.code().value() == ELOOP || e.code().value() == ENAMETOOLONG))
      return kExitBadInput;
    return kExitRunFailed;
  } catch (const nlohmann::json::exception& e) {
    // Every file read back goes through the checked reader: this is a bug, not bad input.
    std::cerr << "dualgrid: error: internal error: a JSON document did not hold what the program "
                 "expected (JSON error "
              << e.id << "; please report it with the command line)\n";
    return kExitRunFailed;
  } catch (const std::logic_error& e) {
    std::cerr << "dualgrid: error: internal error (" << OneLine(e.what())
              << "; please report it with the command line)\n";
    return kExitRunFailed;
  } catch (const std::exception& e) {
    std::cerr << "dualgrid: error: " << OneLine(e.what()) << "\n";
    return kExitRunFailed;
  }
  return kExitOk;
}
