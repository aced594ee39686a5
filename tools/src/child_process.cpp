#include "child_process.hpp"
#include "dualgrid/core/text.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "dualgrid/outputs/read_results.hpp"
#include "signals.hpp"

namespace dualgrid::tools {

pid_t StartChild(std::vector<std::string> args, const std::filesystem::path& log,
                 int* stderr_pipe) {
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string log_path = log.string();
  const pid_t parent = getpid();
  // The child's one line when exec fails (built here: the child may only make async-signal-safe
  // calls, so no formatting or strerror there).
  const std::string exec_error = "dualgrid: error: cannot execute " + args[0] +
                                 " (no such file, or not executable); exit code 127\n";
  int fds[2] = {-1, -1};
  if (stderr_pipe && pipe2(fds, O_CLOEXEC) != 0)
    throw std::runtime_error("cannot start " + args[0] + ": " + std::strerror(errno));
  // fork + exec rather than posix_spawn: the child must die with its parent
  // (PR_SET_PDEATHSIG). Between fork and exec only async-signal-safe calls.
  const pid_t pid = fork();
  if (pid < 0) {
    const int err = errno;
    if (stderr_pipe) close(fds[0]), close(fds[1]);
    throw std::runtime_error("cannot start " + args[0] + ": " + std::strerror(err));
  }
  if (pid == 0) {
    // Its own process group: Ctrl-C on the terminal reaches the parent only, which forwards it
    // once (a run that got SIGINT twice would stop at once, without its partial results).
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(143);  // the parent died before prctl took effect
    // O_APPEND: the parent appends the child's stderr to the same file. A log that cannot be
    // created (a full disk) does not stop a child whose stderr goes to the parent: it runs with
    // stdout discarded, and its error (the reason) still reaches the parent.
    int fd = open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_APPEND, 0644);
    if (fd < 0 && stderr_pipe) fd = open("/dev/null", O_WRONLY);
    if (fd < 0) _exit(126);
    dup2(fd, 1);
    dup2(stderr_pipe ? fds[1] : fd, 2);  // (dup2 clears O_CLOEXEC on the copies)
    close(fd);
    execv(argv[0], argv.data());
    [[maybe_unused]] const ssize_t w = write(2, exec_error.data(), exec_error.size());
    _exit(127);
  }
  if (stderr_pipe) {
    close(fds[1]);
    fcntl(fds[0], F_SETFL, O_NONBLOCK);
    *stderr_pipe = fds[0];
  }
  return pid;
}

bool ChildPool::Free() const { return !StopSignal() && static_cast<int>(running_.size()) < jobs_; }

void ChildPool::Start(std::size_t tag, std::vector<std::string> args,
                      const std::filesystem::path& log) {
  Child c;
  c.tag = tag;
  c.log = log;
  const pid_t pid = StartChild(std::move(args), log, &c.err);
  running_.emplace(pid, std::move(c));
}

void ChildPool::Drain(Child& c) {
  char buf[4096];
  while (c.err >= 0) {
    const ssize_t n = read(c.err, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (n == 0 || errno != EAGAIN) {  // end (the child and what it started closed it)
        close(c.err);
        c.err = -1;
      }
      return;
    }
    // Into the log (appended after the child opened it; a failed write, e.g. a full disk, loses
    // only the log's copy) and into the last line kept in memory.
    if (c.log_fd == -1) {  // once: -2 marks a log that cannot be opened
      c.log_fd = open(c.log.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
      if (c.log_fd < 0) c.log_fd = -2;
    }
    if (c.log_fd >= 0) (void)!write(c.log_fd, buf, static_cast<std::size_t>(n));
    c.tail.append(buf, static_cast<std::size_t>(n));
    if (c.tail.size() > 8192) c.tail.erase(0, c.tail.size() - 4096);
  }
}

std::string ChildPool::Child::LastLine() const {
  std::size_t end = tail.size();
  while (end > 0) {
    const std::size_t start = tail.rfind('\n', end - 1);
    const std::size_t from = start == std::string::npos ? 0 : start + 1;
    if (end > from) return tail.substr(from, end - from);
    if (start == std::string::npos) break;
    end = start;
  }
  return "";
}

std::optional<ChildPool::Ended> ChildPool::Wait() {
  while (true) {
    if (StopSignal() && !forwarded_) {
      for (const auto& [pid, c] : running_) kill(pid, StopSignal());
      forwarded_ = true;
    }
    if (running_.empty()) return std::nullopt;
    // The children's stderr is read as it comes (a full pipe would block them) while waiting;
    // once every pipe is closed, a blocking wait (a signal interrupts it: no SA_RESTART).
    std::vector<pollfd> fds;
    for (const auto& [pid, c] : running_)
      if (c.err >= 0) fds.push_back({c.err, POLLIN, 0});
    if (!fds.empty()) {
      // A child's end closes its pipe (POLLHUP); the timeout only bounds the wait for a child
      // whose pipe outlives it (held by a process it started).
      if (poll(fds.data(), fds.size(), 200) < 0 && errno != EINTR)
        throw std::runtime_error("lost track of " + what_ + ": " + std::strerror(errno));
      for (auto& [pid, c] : running_) Drain(c);
    }
    int status = 0;
    const pid_t pid = waitpid(-1, &status, fds.empty() ? 0 : WNOHANG);
    if (pid == 0) continue;
    if (pid < 0) {
      if (errno == EINTR) continue;  // a signal: forwarded above
      throw std::runtime_error("lost track of " + what_ + ": " + std::strerror(errno));
    }
    const auto it = running_.find(pid);
    if (it == running_.end()) continue;  // not one of ours (e.g. an ffmpeg of this process)
    Child& c = it->second;
    Drain(c);
    if (c.err >= 0) close(c.err);
    if (c.log_fd >= 0) close(c.log_fd);
    Ended e{c.tag, 0, 0, c.LastLine()};
    running_.erase(it);
    e.signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
    e.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + e.signal;
    return e;
  }
}

ChildPool::~ChildPool() {
  for (auto& [pid, c] : running_) {
    if (c.err >= 0) close(c.err);
    if (c.log_fd >= 0) close(c.log_fd);
  }
}

bool RunComplete(const std::filesystem::path& dir) { return outputs::ReadRunState(dir).complete; }

std::string LastLine(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last;
}

std::string ChildFailure(const ChildPool::Ended& ended, const std::filesystem::path& log) {
  if (ended.signal) return "killed by signal " + std::to_string(ended.signal);
  std::string why = ended.last_line.empty() ? LastLine(log) : ended.last_line;
  const std::string prefix = "dualgrid: error: ";
  if (why.rfind(prefix, 0) == 0) why.erase(0, prefix.size());
  return why.empty() ? "exit code " + std::to_string(ended.code) : why;
}

std::string Exact(double v) { return FormatSignificant(v, 17); }

}  // namespace dualgrid::tools
