#include "child_process.hpp"
#include "dualgrid/core/text.hpp"

#include <fcntl.h>
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

#include "signals.hpp"

namespace dualgrid::tools {

pid_t StartChild(std::vector<std::string> args, const std::filesystem::path& log) {
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string log_path = log.string();
  const pid_t parent = getpid();
  // fork + exec rather than posix_spawn: the child must die with its parent
  // (PR_SET_PDEATHSIG). Between fork and exec only async-signal-safe calls.
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("cannot start " + args[0] + ": " + std::strerror(errno));
  if (pid == 0) {
    // Its own process group: Ctrl-C on the terminal reaches the parent only, which forwards it
    // once (a run that got SIGINT twice would stop at once, without its partial results).
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(143);  // the parent died before prctl took effect
    const int fd = open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0) _exit(126);
    dup2(fd, 1);
    dup2(fd, 2);
    close(fd);
    execv(argv[0], argv.data());
    _exit(127);
  }
  return pid;
}

bool ChildPool::Free() const { return !StopSignal() && static_cast<int>(running_.size()) < jobs_; }

void ChildPool::Start(std::size_t tag, std::vector<std::string> args,
                      const std::filesystem::path& log) {
  running_[StartChild(std::move(args), log)] = tag;
}

std::optional<ChildPool::Ended> ChildPool::Wait() {
  while (true) {
    if (StopSignal() && !forwarded_) {
      for (const auto& [pid, tag] : running_) kill(pid, StopSignal());
      forwarded_ = true;
    }
    if (running_.empty()) return std::nullopt;
    int status = 0;
    const pid_t pid = wait(&status);
    if (pid < 0) {
      if (errno == EINTR) continue;  // a signal: forwarded above
      throw std::runtime_error("lost track of " + what_ + ": " + std::strerror(errno));
    }
    const auto it = running_.find(pid);
    if (it == running_.end()) continue;  // not one of ours (e.g. an ffmpeg of this process)
    Ended e{it->second, 0, 0};
    running_.erase(it);
    e.signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
    e.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + e.signal;
    return e;
  }
}

bool RunComplete(const std::filesystem::path& dir) {
  try {
    std::ifstream in(dir / "summary.json");
    return in && nlohmann::json::parse(in).value("complete", false);
  } catch (const std::exception&) {
    return false;
  }
}

std::string LastLine(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last;
}

std::string Exact(double v) { return FormatSignificant(v, 17); }

}  // namespace dualgrid::tools
