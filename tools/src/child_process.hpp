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
/// behind. With `stderr_pipe`, stderr goes to a pipe instead, whose (non-blocking) read end is
/// stored there for the caller to read and append to the log. Throws std::runtime_error if fork
/// fails.
pid_t StartChild(std::vector<std::string> args, const std::filesystem::path& log,
                 int* stderr_pipe = nullptr);

/// Child processes run `jobs` at a time, each known by a caller's tag (a seed, a run's index):
/// the one pool of `experiment` and `sweep`. A stop signal (signals.hpp) is forwarded once to
/// every running child, which stops at the end of its step and writes its part; no new child is
/// started after it.
class ChildPool {
 public:
  /// `what` names the children in errors ("the seed runs").
  ChildPool(int jobs, std::string what) : jobs_(jobs), what_(std::move(what)) {}
  ~ChildPool();
  ChildPool(const ChildPool&) = delete;
  ChildPool& operator=(const ChildPool&) = delete;
  /// Room for one more child, and no stop signal.
  bool Free() const;
  /// StartChild(args, log), remembered under `tag`. Its stderr is read by Wait, appended to
  /// `log` and its last line kept: the reason a run failed survives a log that cannot be written
  /// (a full disk).
  void Start(std::size_t tag, std::vector<std::string> args, const std::filesystem::path& log);
  struct Ended {
    std::size_t tag = 0;
    int code = 0;           ///< the exit code, or 128 + the signal that killed it
    int signal = 0;         ///< the signal that killed it, 0 if it exited
    std::string last_line;  ///< the last non-empty line it wrote to stderr
  };
  /// Waits for the next child to end; std::nullopt when none is running. Throws
  /// std::runtime_error if the children cannot be waited for.
  std::optional<Ended> Wait();

 private:
  struct Child {
    std::size_t tag = 0;
    std::filesystem::path log;
    int err = -1;      ///< read end of its stderr pipe
    int log_fd = -1;   ///< the log, opened for appending at the first stderr bytes (-2: cannot)
    std::string tail;  ///< the end of its stderr
    std::string LastLine() const;
  };
  void Drain(Child& c);

  int jobs_;
  std::string what_;
  std::map<pid_t, Child> running_;
  bool forwarded_ = false;
};

/// A run folder is finished only when its summary.json, written last, says "complete": true.
bool RunComplete(const std::filesystem::path& dir);

/// The last non-empty line of a file (a run's log: its error message); "" if none.
std::string LastLine(const std::filesystem::path& path);

/// Why a child ended without finishing, in one line: the signal that killed it, else the last
/// line of its stderr as the pool read it (kept though `log` could not be written, e.g. on a
/// full disk) without its "dualgrid: error: " prefix, else the last line of `log`, else its exit
/// code.
std::string ChildFailure(const ChildPool::Ended& ended, const std::filesystem::path& log);

/// Exact decimal text of a double (std::to_string rounds to 6 decimals).
std::string Exact(double v);

}  // namespace dualgrid::tools
