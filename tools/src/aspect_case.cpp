#include "aspect_case.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "dualgrid/outputs/output_file.hpp"

extern char** environ;

namespace dualgrid::tools {
namespace {

// Runs netconvert on the plain-XML files; its output goes to `log`.
void Netconvert(const std::filesystem::path& nod, const std::filesystem::path& edg,
                const std::filesystem::path& net, const std::filesystem::path& log) {
  const std::string exe = DUALGRID_NETCONVERT;
  std::vector<std::string> args = {
      exe,          "--node-files",     nod.string(), "--edge-files",
      edg.string(), "--no-turnarounds", "true",       "--offset.disable-normalization",
      "true",       "--xml-validation", "never",      "--no-warnings",
      "true",       "--output-file",    net.string()};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  // SUMO_HOME for netconvert's data files, unless the user set it.
  std::vector<std::string> env_store;
  for (char** e = environ; *e; ++e) env_store.emplace_back(*e);
  if (!std::getenv("SUMO_HOME"))
    env_store.push_back(std::string("SUMO_HOME=") + DUALGRID_SUMO_HOME);
  std::vector<char*> envp;
  for (auto& e : env_store) envp.push_back(e.data());
  envp.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, exe.c_str(), &fa, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0)
    throw std::runtime_error("cannot start netconvert (" + exe + "): " + std::strerror(rc));
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR)
      throw std::runtime_error("lost netconvert: " + std::string(std::strerror(errno)));
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw std::runtime_error("netconvert failed building " + net.string() + " (see " +
                             log.string() + ")");
}

}  // namespace

std::string WriteAspectCase(const scenario::AspectCase& c, const std::filesystem::path& out) {
  const scenario::AspectCaseFiles f = scenario::MakeAspectCase(c, out.stem().string());
  const std::filesystem::path base = out.parent_path() / out.stem();
  const auto nod_path = base.string() + ".nod.xml", edg_path = base.string() + ".edg.xml",
             net_path = base.string() + ".net.xml", log_path = base.string() + ".netconvert.log";
  outputs::WriteTextFile(nod_path, f.nodes);
  outputs::WriteTextFile(edg_path, f.edges);
  Netconvert(nod_path, edg_path, net_path, log_path);
  outputs::WriteTextFile(out, f.scenario);
  return f.summary;
}

}  // namespace dualgrid::tools
