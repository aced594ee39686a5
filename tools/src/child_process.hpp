// Starting `dualgrid run` child processes (experiment, sweep) and reading their results back.
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace dualgrid::tools {

/// Starts `args[0]` with `args` in its own process group, stdout and stderr to `log`; the child
/// gets SIGTERM when this process dies (PR_SET_PDEATHSIG), so a killed parent leaves no runs
/// behind. Throws std::runtime_error if fork fails.
pid_t StartChild(std::vector<std::string> args, const std::filesystem::path& log);

/// Child processes run `jobs` at a time, each known by a caller's tag (a seed, a run's index):
/// the one pool of `experiment` and `sweep`. A stop signal (signals.hpp) is forwarded once to
/// every running child, which stops at the end of its step and writes its part; no new child is
/// started after it.
class ChildPool {
 public:
  /// `what` names the children in errors ("the seed runs").
  ChildPool(int jobs, std::string what) : jobs_(jobs), what_(std::move(what)) {}
  /// Room for one more child, and no stop signal.
  bool Free() const;
  /// StartChild(args, log), remembered under `tag`.
  void Start(std::size_t tag, std::vector<std::string> args, const std::filesystem::path& log);
  struct Ended {
    std::size_t tag = 0;
    int code = 0;    ///< the exit code, or 128 + the signal that killed it
    int signal = 0;  ///< the signal that killed it, 0 if it exited
  };
  /// Waits for the next child to end; std::nullopt when none is running. Throws
  /// std::runtime_error if the children cannot be waited for.
  std::optional<Ended> Wait();

 private:
  int jobs_;
  std::string what_;
  std::map<pid_t, std::size_t> running_;
  bool forwarded_ = false;
};

/// A run folder is finished only when its summary.json, written last, says "complete": true.
bool RunComplete(const std::filesystem::path& dir);

/// The last non-empty line of a file (a run's log: its error message); "" if none.
std::string LastLine(const std::filesystem::path& path);

/// Exact decimal text of a double (std::to_string rounds to 6 decimals).
std::string Exact(double v);

}  // namespace dualgrid::tools
