// The exit codes of every dualgrid subcommand (documented in docs/cli.md and in `--help`).
#pragma once

namespace dualgrid::tools {

enum ExitCode : int {
  kExitOk = 0,
  /// The run failed while running: SUMO stopped with an error, an output could not be written.
  kExitRunFailed = 1,
  /// Bad input: the command line, the scenario file or a network file; nothing was simulated.
  /// Thrown inside the program as std::invalid_argument or scenario::ConfigError.
  kExitBadInput = 2,
  /// `experiment`: some seed runs failed; the others were aggregated and the failures named.
  kExitSomeSeedsFailed = 3,
};

}  // namespace dualgrid::tools
