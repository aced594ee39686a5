// Starting `dualgrid run` child processes (experiment, sweep) and reading their results back.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <string>
#include <vector>

namespace dualgrid::tools {

/// Starts `args[0]` with `args` in its own process group, stdout and stderr to `log`; the child
/// gets SIGTERM when this process dies (PR_SET_PDEATHSIG), so a killed parent leaves no runs
/// behind. Throws std::runtime_error if fork fails.
pid_t StartChild(std::vector<std::string> args, const std::filesystem::path& log);

/// A run folder is finished only when its summary.json, written last, says "complete": true.
bool RunComplete(const std::filesystem::path& dir);

/// The last non-empty line of a file (a run's log: its error message); "" if none.
std::string LastLine(const std::filesystem::path& path);

/// Exact decimal text of a double (std::to_string rounds to 6 decimals).
std::string Exact(double v);

}  // namespace dualgrid::tools
