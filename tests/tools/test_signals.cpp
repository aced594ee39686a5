// Runs that end early (docs/reliability.md): real signals sent to real runs (SIGINT and SIGTERM
// stop at the end of a step and leave the simulated part's results marked incomplete; experiment
// forwards them; a killed experiment takes its runs with it; a killed run never looks finished),
// and a run whose ego leaves the network before the requested duration.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_harness.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using namespace dualgrid::testing;

namespace {

fs::path TempDir(const std::string& name) { return dualgrid::testing::TempDir("signals", name); }

// Starts dualgrid with `args`, output to `log`; returns its pid.
pid_t Start(const std::vector<std::string>& args, const fs::path& log) {
  const pid_t pid = fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    setpgid(0, 0);  // its own process group, as a shell gives a foreground job
    std::freopen(log.c_str(), "w", stdout);
    dup2(fileno(stdout), 2);
    std::vector<char*> argv{const_cast<char*>(DUALGRID_EXE)};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(DUALGRID_EXE, argv.data());
    _exit(127);
  }
  return pid;
}

// Waits until `path` exists (the run has got going), at most `limit`.
bool WaitFor(const fs::path& path, std::chrono::seconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < end) {
    if (fs::exists(path)) return true;
    std::this_thread::sleep_for(50ms);
  }
  return false;
}

int ExitCode(pid_t pid) {
  int status = 0;
  REQUIRE(waitpid(pid, &status, 0) == pid);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// Processes whose command line mentions `text` (the runs of one test's output folder).
int ProcessesMentioning(const std::string& text) {
  int n = 0;
  for (const auto& e : fs::directory_iterator("/proc")) {
    const std::string pid = e.path().filename().string();
    if (pid.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream in(e.path() / "cmdline");
    std::string cmd((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ifstream st(e.path() / "stat");
    std::string stat((std::istreambuf_iterator<char>(st)), std::istreambuf_iterator<char>());
    const bool zombie = stat.find(") Z ") != std::string::npos;
    if (!zombie && cmd.find(text) != std::string::npos) ++n;
  }
  return n;
}

}  // namespace

TEST_CASE("SIGINT and SIGTERM stop a run with its partial results marked incomplete",
          "[cli][signals]") {
  const int sig = GENERATE(SIGINT, SIGTERM);
  const auto dir = TempDir("run_" + std::to_string(sig));
  const pid_t pid =
      Start({"run", "scenarios/highway.yaml", "--no-figures", "-q", "--out", dir.string()},
            dir.parent_path() / ("run_" + std::to_string(sig) + ".log"));
  // clusters.csv is created when the first step starts; give it a few steps more.
  REQUIRE(WaitFor(dir / "clusters.csv", 600s));
  std::this_thread::sleep_for(1s);
  kill(pid, sig);
  CHECK(ExitCode(pid) == 128 + sig);
  const auto summary = nlohmann::json::parse(Slurp(dir / "summary.json"));
  CHECK(summary.at("complete") == false);
  CHECK(summary.at("simulated_s").get<double>() < summary.at("requested_s").get<double>());
  CHECK(
      Slurp(dir / "table.md").find("**Incomplete run: stopped by signal " + std::to_string(sig)) !=
      std::string::npos);
  const auto metrics = nlohmann::json::parse(Slurp(dir / "metrics.json"));
  CHECK(metrics.at("steps").get<int>() > 0);
}

TEST_CASE("experiment forwards SIGTERM to its runs and keeps the finished seeds",
          "[cli][signals]") {
  const auto dir = TempDir("experiment");
  // One seed at a time: seed 1 finishes; seed 2 is still running when the signal comes (it needs
  // a few seconds, or minutes under a sanitizer).
  const pid_t pid = Start({"experiment", "scenarios/highway.yaml", "--seeds", "2", "-j", "1",
                           "--duration", "20", "--no-figures", "-q", "--out", dir.string()},
                          dir.parent_path() / "experiment.log");
  REQUIRE(WaitFor(dir / "seeds" / "seed_2" / "clusters.csv", 900s));
  std::this_thread::sleep_for(1s);
  // To the experiment alone (kill PID), or to its process group as Ctrl-C on a terminal does:
  // either way its runs get the signal once, from the experiment, and stop cleanly.
  const bool group = GENERATE(false, true);
  INFO((group ? "process group" : "parent only"));
  kill(group ? -pid : pid, SIGTERM);
  CHECK(ExitCode(pid) == 143);
  CHECK(ProcessesMentioning(dir.string()) == 0);
  const auto summary = nlohmann::json::parse(Slurp(dir / "summary.json"));
  CHECK(summary.at("complete") == false);
  CHECK(summary.at("seeds_finished") == nlohmann::json::array({1}));
  CHECK(summary.at("seeds_cut_short") == nlohmann::json::array({2}));
  const auto seed2 = nlohmann::json::parse(Slurp(dir / "seeds" / "seed_2" / "summary.json"));
  CHECK(seed2.at("complete") == false);
  CHECK(Slurp(dir / "table.csv").find("highway,D,%,dual,1,") != std::string::npos);
}

TEST_CASE("A killed experiment takes its runs with it", "[cli][signals]") {
  const auto dir = TempDir("orphans");
  const pid_t pid = Start({"experiment", "scenarios/highway.yaml", "--seeds", "2", "-j", "2",
                           "--no-figures", "-q", "--out", dir.string()},
                          dir.parent_path() / "orphans.log");
  REQUIRE(WaitFor(dir / "seeds" / "seed_2" / "clusters.csv", 900s));
  kill(pid, SIGKILL);
  CHECK(ExitCode(pid) == 128 + SIGKILL);
  // The runs get SIGTERM from the kernel (PR_SET_PDEATHSIG) and stop at the end of their step.
  const auto end = std::chrono::steady_clock::now() + 20s;
  while (ProcessesMentioning(dir.string()) > 0 && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(100ms);
  CHECK(ProcessesMentioning(dir.string()) == 0);
}

TEST_CASE("A run killed in a folder of an earlier finished run does not look finished",
          "[cli][signals]") {
  const auto dir = TempDir("reuse");
  const std::string exe = DUALGRID_EXE;
  REQUIRE(std::system((exe +
                       " run scenarios/simple_road.yaml --duration 1 --no-figures -q "
                       "--out " +
                       dir.string())
                          .c_str()) == 0);
  REQUIRE(fs::exists(dir / "summary.json"));
  const pid_t pid = Start(
      {"run", "scenarios/simple_road.yaml", "--no-figures", "-q", "--force", "--out", dir.string()},
      dir.parent_path() / "reuse.log");
  // The earlier run's completion record goes before the new run writes anything.
  const auto end = std::chrono::steady_clock::now() + 60s;
  while (fs::exists(dir / "summary.json") && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(20ms);
  REQUIRE_FALSE(fs::exists(dir / "summary.json"));
  std::this_thread::sleep_for(1s);
  kill(pid, SIGKILL);
  CHECK(ExitCode(pid) == 128 + SIGKILL);
  CHECK_FALSE(fs::exists(dir / "summary.json"));
}

TEST_CASE("A run whose ego leaves the network ends there, complete, and says so",
          "[cli][signals]") {
  const auto dir = TempDir("short");
  // The route ends about 450 m ahead of the ego, which drives 27.78 m/s: SUMO ends near 16 s.
  std::ofstream(dir / "short.yaml")
      << "network: highway\nduration: 20.0\nroutes: {short: [east_1, east_2]}\n"
         "ego: {type: car, route: short, lane: 1, position: 1350, speed: 27.78,\n"
         "      speed_policy: {mode: fixed, speed: 27.78}}\n";
  const pid_t pid = Start({"run", (dir / "short.yaml").string(), "--modes", "dual", "--no-figures",
                           "-q", "--out", (dir / "out").string()},
                          dir / "log.txt");
  CHECK(ExitCode(pid) == 0);
  const std::string log = Slurp(dir / "log.txt");
  CHECK(log.find("dualgrid: Shorter run than asked: the ego 'ego' left the network at t = ") !=
        std::string::npos);
  CHECK(CountLines(log) == 1);
  // The scenario ended with its ego: the run is complete, and summary.json says how it ended.
  const auto summary = nlohmann::json::parse(Slurp(dir / "out" / "summary.json"));
  CHECK(summary.at("complete") == true);
  CHECK(summary.at("end") == "ego_left");
  CHECK(summary.at("ended_s").get<double>() < 18.0);
  CHECK(summary.at("simulated_s").get<double>() < 18.0);
  CHECK(Slurp(dir / "out" / "table.md").find("**Shorter run than asked") != std::string::npos);
}
