// SUMO's programs run as child processes: `sumo` asked what a configuration holds, `netconvert`
// turning OpenDRIVE maps into SUMO networks, `randomTrips.py` writing traffic (sumo-tools).
// libsumo (sumo_simulation.hpp) runs the simulation itself, in process.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace dualgrid::sim {

/// SUMO's data folder: $SUMO_HOME when set, else the one found at build time (Debian's
/// /usr/share/sumo). Its tools/ holds randomTrips.py.
std::filesystem::path SumoHome();

/// Runs `args` (args[0] a program found on PATH, e.g. "sumo", "netconvert", "python3") to its
/// end with stdin closed and stdout and stderr written to `log`, SUMO_HOME set to SumoHome()
/// unless the environment sets it. Returns the exit code (128 + the signal that killed it).
/// Throws std::runtime_error naming the program when it cannot be started (not installed).
int RunSumoTool(const std::vector<std::string>& args, const std::filesystem::path& log);

/// The first line of a SUMO program's log that reports an error ("Error: ..." for sumo and
/// netconvert, a Python traceback's last line for the Python tools), else its last non-empty
/// line; "" for an empty or unreadable log. Trimmed to one line of at most 300 characters, bytes
/// outside printable ASCII shown as '?' (a tool may quote a binary input's bytes).
std::string FirstErrorLine(const std::filesystem::path& log);

}  // namespace dualgrid::sim
