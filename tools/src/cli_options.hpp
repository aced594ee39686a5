// How the subcommands register themselves and the options several of them share. Each command's
// own options live in its cmd_*.cpp (AddXCommand); main() only lists the commands.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli_checks.hpp"
#include "commands.hpp"

namespace dualgrid::tools {

/// What every command may need from the program itself.
struct CliContext {
  std::filesystem::path network_dir;  ///< default --network-dir (sim::FindNetworkDir)
  std::string executable;             ///< this program, to start child runs
};

/// A registered subcommand: `run` is called when `app` was the one parsed; it returns the exit
/// code and throws for errors (reported in one line by main()).
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

// One per subcommand, each in its cmd_*.cpp.
Command AddSimCommand(CLI::App& app, const CliContext& ctx);
Command AddSnapshotCommand(CLI::App& app, const CliContext& ctx);
Command AddRunCommand(CLI::App& app, const CliContext& ctx);
Command AddReplayCommand(CLI::App& app, const CliContext& ctx);
Command AddExperimentCommand(CLI::App& app, const CliContext& ctx);
Command AddTangentialCommand(CLI::App& app, const CliContext& ctx);
Command AddRegressCommand(CLI::App& app, const CliContext& ctx);
Command AddSweepCommand(CLI::App& app, const CliContext& ctx);
Command AddCollectCommand(CLI::App& app, const CliContext& ctx);
Command AddFilterCommand(CLI::App& app, const CliContext& ctx);
Command AddExportCommand(CLI::App& app, const CliContext& ctx);

/// An option whose default is shown in --help.
template <typename T>
CLI::Option* Opt(CLI::App* cmd, const std::string& name, T* value, const std::string& help) {
  return cmd->add_option(name, *value, help)->capture_default_str();
}

/// The options of every command that runs a scenario: scenario, --out, [--seed], --duration,
/// --network-dir, --quiet, --set.
void AddRunOptions(CLI::App* cmd, RunOptions* o, const std::string& out_help, bool with_seed);
/// The options of the commands that run the filters (run, experiment); `*no_figures` receives
/// --no-figures.
void AddFilterOptions(CLI::App* cmd, FilterRunOptions* o, bool* no_figures);
/// `--figure-captions on|off` into `*captions`.
void AddCaptionOption(CLI::App* cmd, bool* captions);
/// `--force` into `*force`: replace an earlier dualgrid output in --out (output_guard.hpp).
void AddForceFlag(CLI::App* cmd, bool* force);
/// none, csv or csv.gz.
CLI::Validator DetectionFormat();

}  // namespace dualgrid::tools
