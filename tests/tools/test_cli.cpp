// Runs the dualgrid program as a user would and checks its output and errors.
#include <catch2/catch.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace {

struct Result {
  int code;
  std::string output;  // stdout and stderr
};

Result Run(const std::string& args) {
  const std::string cmd = std::string(DUALGRID_EXE) + " " + args + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  REQUIRE(pipe != nullptr);
  std::string out;
  char buf[4096];
  while (std::size_t n = std::fread(buf, 1, sizeof buf, pipe)) out.append(buf, n);
  const int status = pclose(pipe);
  return {WEXITSTATUS(status), out};
}

std::string Slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

fs::path TempDir(const std::string& name) {
  const auto d = fs::temp_directory_path() / ("dualgrid_cli_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

int CountLines(const std::string& s) {
  return static_cast<int>(std::count(s.begin(), s.end(), '\n'));
}

}  // namespace

TEST_CASE("--help lists the subcommands", "[cli]") {
  const Result r = Run("--help");
  CHECK(r.code == 0);
  CHECK(r.output.find("sim") != std::string::npos);
}

TEST_CASE("Same scenario and seed give identical ground truth; another seed differs", "[cli]") {
  const auto a = TempDir("a"), b = TempDir("b"), c = TempDir("c");
  const std::string common = "sim scenarios/highway.yaml --duration 12 -q ";
  REQUIRE(Run(common + "--out " + a.string()).code == 0);
  REQUIRE(Run(common + "--out " + b.string()).code == 0);
  REQUIRE(Run(common + "--seed 7 --out " + c.string()).code == 0);
  const std::string ta = Slurp(a / "ground_truth.csv");
  CHECK(CountLines(ta) > 240 * 5);  // 240 steps, several vehicles each
  CHECK(ta == Slurp(b / "ground_truth.csv"));
  // The seed draws the oncoming flow's desired speeds.
  CHECK(ta != Slurp(c / "ground_truth.csv"));
}

TEST_CASE("Errors are one line with a non-zero exit", "[cli]") {
  const auto dir = TempDir("errors");
  SECTION("missing network") {
    std::ofstream(dir / "s.yaml") << "network: atlantis\nego: {type: car, route: r}\n"
                                     "routes: {r: [e]}\n";
    const Result r = Run("sim " + (dir / "s.yaml").string() + " --out " + (dir / "o").string());
    CHECK(r.code != 0);
    CHECK(CountLines(r.output) == 1);
    CHECK(r.output.find("network 'atlantis' not found") != std::string::npos);
  }
  SECTION("malformed scenario") {
    std::ofstream(dir / "s.yaml") << "network: highway\nduration: soon\n";
    const Result r = Run("sim " + (dir / "s.yaml").string() + " --out " + (dir / "o").string());
    CHECK(r.code != 0);
    CHECK(CountLines(r.output) == 1);
    CHECK(r.output.find("'duration' expected a number") != std::string::npos);
  }
  SECTION("SUMO error: an edge missing from the network") {
    std::ofstream(dir / "s.yaml") << "network: highway\nego: {type: car, route: r}\n"
                                     "routes: {r: [no_such_edge]}\n";
    const Result r = Run("sim " + (dir / "s.yaml").string() + " --out " + (dir / "o").string());
    CHECK(r.code != 0);
    CHECK(CountLines(r.output) == 1);
    CHECK(r.output.find("SUMO") != std::string::npos);
  }
}
