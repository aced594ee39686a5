#include "dualgrid/sim/sumo_tools.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <stdexcept>

extern char** environ;

namespace dualgrid::sim {

std::filesystem::path SumoHome() {
  if (const char* home = std::getenv("SUMO_HOME"); home && *home) return home;
  return DUALGRID_SUMO_HOME;
}

int RunSumoTool(const std::vector<std::string>& args, const std::filesystem::path& log) {
  std::vector<std::string> arg_text = args;
  std::vector<char*> argv;
  for (std::string& a : arg_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_text;
  for (char** e = environ; *e; ++e) env_text.emplace_back(*e);
  if (const char* home = std::getenv("SUMO_HOME"); !home || !*home)
    env_text.push_back("SUMO_HOME=" + SumoHome().string());
  std::vector<char*> envp;
  for (std::string& e : env_text) envp.push_back(e.data());
  envp.push_back(nullptr);
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&files, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&files, 1, 2);
  pid_t pid = 0;
  const int started = posix_spawnp(&pid, argv[0], &files, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&files);
  if (started != 0)
    throw std::runtime_error("cannot start " + args.front() + " (" + std::strerror(started) +
                             "; it comes with Debian's sumo and sumo-tools packages)");
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR)
      throw std::runtime_error("lost " + args.front() + ": " + std::strerror(errno));
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

std::string FirstErrorLine(const std::filesystem::path& log) {
  std::ifstream in(log);
  std::string line, last, python_error;
  while (std::getline(in, line)) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    if (line.empty()) continue;
    if (line.rfind("Error:", 0) == 0) {
      last = line;
      break;
    }
    // A Python traceback ends with "SomeError: message".
    if (line.find("Error: ") != std::string::npos && line[0] != ' ') python_error = line;
    last = line;
  }
  if (!python_error.empty() && last.rfind("Error:", 0) != 0) last = python_error;
  if (last.size() > 300) last = last.substr(0, 297) + "...";
  // The tool may quote the bytes of a binary input: one printable line.
  for (char& c : last)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
  return last;
}

}  // namespace dualgrid::sim
