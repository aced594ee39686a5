// SIGINT and SIGTERM end a run cleanly: the current step finishes, the results of the simulated
// part are written marked incomplete, and the process exits with 128 + the signal's number
// (130, 143). A second signal ends the process at once.
#pragma once

namespace dualgrid::tools {

/// Installs the handlers (without SA_RESTART, so a blocking wait() returns with EINTR).
void InstallStopHandlers();
/// The signal that asked to stop, or 0.
int StopSignal();
/// 128 + StopSignal(): the exit code of a stopped run.
int StopExitCode();

}  // namespace dualgrid::tools
