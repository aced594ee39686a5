// A new user's first hour (issue 9): readable errors with documented exit codes, results that
// survive a failing figure or seed, scenario-relative paths, and every output documented.
#include <sys/wait.h>

#include <catch2/catch.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_harness.hpp"

namespace fs = std::filesystem;
using namespace dualgrid::testing;

namespace {

fs::path TempDir(const std::string& name) { return dualgrid::testing::TempDir("newcomer", name); }

// One line on stderr, starting "dualgrid: error:", naming `what`, with no runaway number.
void CheckOneLineError(const Result& r, int code, const std::string& what) {
  INFO(r.output);
  CHECK(r.code == code);
  CHECK(CountLines(r.output) == 1);
  CHECK(r.output.rfind("dualgrid: error: ", 0) == 0);
  CHECK(r.output.find(what) != std::string::npos);
  CHECK(r.output.size() < 400);
}

}  // namespace

TEST_CASE("Bad command-line values: one readable line, exit code 2", "[cli][newcomer]") {
  const std::string out = " --out " + (fs::temp_directory_path() / "dualgrid_never").string();
  CheckOneLineError(Run("experiment scenarios/highway.yaml --seeds 0" + out), 2, "--seeds");
  CheckOneLineError(Run("run scenarios/highway.yaml --threads -1" + out), 2, "--threads");
  CheckOneLineError(Run("run scenarios/highway.yaml --threads 100000" + out), 2, "--threads");
  CheckOneLineError(Run("run scenarios/highway.yaml --seed -1" + out), 2, "--seed");
  CheckOneLineError(Run("run scenarios/highway.yaml --duration ''" + out), 2, "--duration");
  CheckOneLineError(Run("experiment scenarios/highway.yaml -j 0" + out), 2, "--jobs");
  CheckOneLineError(Run("experiment scenarios/highway.yaml -j -3" + out), 2, "--jobs");
  CheckOneLineError(Run("experiment scenarios/highway.yaml --seed 3" + out), 2, "--seed");
  CheckOneLineError(Run("snapshot scenarios/highway.yaml -t 3 --behind -5 --out /tmp/x.png"), 2,
                    "--behind");
  CheckOneLineError(Run("run scenarios/highway.yaml --modes dual,fancy" + out), 2, "--modes");
  CheckOneLineError(Run("run" + out), 2, "scenario");
  CheckOneLineError(Run("run scenarios/highway.yaml --out ''"), 2, "--out");
  CheckOneLineError(Run("tangential --kind parallel --ego-speed 20 --speed 30 --out /tmp/t.yaml"),
                    2, "--speed");
  CHECK_FALSE(fs::exists(fs::temp_directory_path() / "dualgrid_never"));
}

TEST_CASE("Help shows defaults, documents exit codes, and lists only valid options",
          "[cli][newcomer]") {
  const Result tangential = Run("tangential --help");
  CHECK(tangential.code == 0);
  CHECK(tangential.output.find("--count INT:INT in [1, 12]=4") != std::string::npos);
  CHECK(tangential.output.find("default: crossing 15") != std::string::npos);
  const Result experiment = Run("experiment --help");
  CHECK(experiment.output.find("--seed ") == std::string::npos);
  CHECK(experiment.output.find("--seeds") != std::string::npos);
  CHECK(experiment.output.find("{false}") == std::string::npos);
  CHECK(experiment.output.find("--no-figures ") != std::string::npos);
  const Result top = Run("--help");
  CHECK(top.output.find("Exit codes: 0") != std::string::npos);
  // Every code named in --help is explained in docs/cli.md.
  const std::string doc = Slurp("docs/cli.md");
  for (const char* code : {"| 0 |", "| 1 |", "| 2 |", "| 3 |"})
    CHECK(doc.find(code) != std::string::npos);
}

TEST_CASE("tangential --speed is the speed over ground for both kinds", "[cli][newcomer]") {
  const auto dir = TempDir("speed");
  REQUIRE(Run("tangential --kind parallel --ego-speed 20 --speed 21 -q --out " +
              (dir / "p.yaml").string())
              .code == 0);
  const std::string p = Slurp(dir / "p.yaml");
  CHECK(p.find("speed: 21, desired_speed: 21") != std::string::npos);
  REQUIRE(
      Run("tangential --kind parallel --ego-speed 20 -q --out " + (dir / "d.yaml").string()).code ==
      0);
  CHECK(Slurp(dir / "d.yaml").find("speed: 20.3, desired_speed: 20.3") != std::string::npos);
  REQUIRE(Run("tangential --kind crossing --speed 12 -q --out " + (dir / "c.yaml").string()).code ==
          0);
  CHECK(Slurp(dir / "c.yaml").find("speed: 12, desired_speed: 12") != std::string::npos);
}

TEST_CASE("snapshot writes only the picture it is asked for", "[cli][newcomer]") {
  const auto dir = TempDir("snapshot");
  CheckOneLineError(
      Run("snapshot scenarios/highway.yaml -t 2 -q --out " + (dir / "s.jpg").string()), 2,
      "ending in .png, .svg or .pdf");
  REQUIRE(Run("snapshot scenarios/highway.yaml -t 2 -q --out " + (dir / "s.png").string()).code ==
          0);
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  CHECK(names == std::set<std::string>{"s.png"});
}

TEST_CASE("A network path is read relative to the scenario file", "[cli][newcomer]") {
  const auto dir = TempDir("relative");
  fs::create_directories(dir / "nets");
  fs::copy_file(fs::path(DUALGRID_NETWORK_DIR) / "simple_road.net.xml",
                dir / "nets" / "road.net.xml");
  std::string text = Slurp("scenarios/simple_road.yaml");
  text = std::regex_replace(text, std::regex("\nnetwork: simple_road\n"),
                            "\nnetwork: nets/road.net.xml\n");
  REQUIRE(text.find("nets/road.net.xml") != std::string::npos);
  std::ofstream(dir / "s.yaml") << text;
  // Run from the repository (the test's working folder), not from the scenario's folder.
  const Result ok = Run("sim " + (dir / "s.yaml").string() + " --duration 1 -q --detections none " +
                        "--out " + (dir / "o").string());
  INFO(ok.output);
  CHECK(ok.code == 0);
  CHECK(Slurp(dir / "o" / "scenario.yaml").find((dir / "nets" / "road.net.xml").string()) !=
        std::string::npos);
  std::ofstream(dir / "bad.yaml") << std::regex_replace(text, std::regex("nets/road"), "nets/none");
  CheckOneLineError(Run("sim " + (dir / "bad.yaml").string() + " --out " + (dir / "o2").string()),
                    2, "relative to the scenario file");
  CheckOneLineError(Run("sim " + (dir / "bad.yaml").string() + " --out " + (dir / "o2").string()),
                    2, (dir / "nets" / "none.net.xml").string());
}

TEST_CASE("A figure that fails is a warning; the results are all there", "[cli][newcomer]") {
  const auto dir = TempDir("figure_fails");
  // The test hook makes drawing this figure throw (docs/reliability.md).
  const Result r = Shell("DUALGRID_FAULT=figure:tracked_share.png " + std::string(DUALGRID_EXE) +
                         " run scenarios/simple_road.yaml --duration 2 --out " + dir.string());
  INFO(r.output);
  CHECK(r.code == 0);
  CHECK(r.output.find("dualgrid: warning: figure " +
                      (dir / "figures" / "tracked_share.png").string() + " not drawn") !=
        std::string::npos);
  CHECK(r.output.find("| D [%] |") != std::string::npos);  // the table is printed
  for (const char* f : {"metrics.json", "objects.csv", "table.md", "table.csv", "table.json",
                        "weights.csv", "summary.json", "figures/weights.png"})
    CHECK(fs::file_size(dir / f) > 0);
  CHECK_FALSE(fs::exists(dir / "figures" / "tracked_share.png"));
  const auto summary = nlohmann::json::parse(Slurp(dir / "summary.json"));
  CHECK(summary.at("complete") == true);
  CHECK(summary.at("warnings").size() == 1);
  // A single run claims no interval over one seed.
  CHECK(r.output.find("over 1 seed") == std::string::npos);
  CHECK(r.output.find("One seed") != std::string::npos);
}

TEST_CASE("experiment aggregates the seeds that finished and names the failed one",
          "[cli][newcomer]") {
  const auto dir = TempDir("seed_fails");
  // The test hook makes seed 2's run fail after its simulation.
  const Result r = Shell("DUALGRID_FAULT=run-seed:2 " + std::string(DUALGRID_EXE) +
                         " experiment scenarios/simple_road.yaml --seeds 2 --duration 2 "
                         "--no-figures -q --out " +
                         dir.string());
  INFO(r.output);
  CHECK(r.code == 3);
  CHECK(r.output.find("seed 2 failed: injected fault") != std::string::npos);
  CHECK(r.output.find("failed: dualgrid: error:") == std::string::npos);  // the reason, once
  const std::string table = Slurp(dir / "table.csv");
  CHECK(table.find("simple_road,D,%,dual,1,") != std::string::npos);  // seed 1 only
  CHECK(Slurp(dir / "table.md").find("Seed 2 failed") != std::string::npos);
  const auto summary = nlohmann::json::parse(Slurp(dir / "summary.json"));
  CHECK(summary.at("complete") == false);
  CHECK(summary.at("seeds_failed").at(0).at("seed") == 2);
}

TEST_CASE("An output folder never mixes two runs", "[cli][newcomer]") {
  const auto dir = TempDir("reuse_folder");
  const std::string run = "run scenarios/simple_road.yaml --duration 1 --no-figures -q --out ";
  REQUIRE(Run(run + dir.string() + " --detections csv").code == 0);
  REQUIRE(fs::exists(dir / "detections.csv"));
  // Without --force a folder that is not empty is never touched: the user is told what to do.
  CheckOneLineError(Run(run + dir.string()), 2, "add --force");
  CHECK(fs::exists(dir / "detections.csv"));
  // With --force, the earlier run's own files go; a file the user put there stays.
  std::ofstream(dir / "notes.txt") << "mine";
  REQUIRE(Run(run + dir.string() + " --force").code == 0);
  CHECK_FALSE(fs::exists(dir / "detections.csv"));
  CHECK(fs::exists(dir / "summary.json"));
  CHECK(Slurp(dir / "notes.txt") == "mine");
  // A folder of other files is never cleared, not even with --force.
  const auto other = TempDir("other_folder");
  std::ofstream(other / "thesis.tex") << "precious";
  CheckOneLineError(Run(run + other.string()), 2, "is not empty");
  CheckOneLineError(Run(run + other.string() + " --force"), 2, "not a dualgrid output");
  CHECK(Slurp(other / "thesis.tex") == "precious");
}

TEST_CASE("A write past a file-size limit is an error naming the file", "[cli][newcomer]") {
  const auto dir = TempDir("file_limit");
  // 64 KiB per file: config.json fits, ground_truth.csv of 20 s does not.
  const Result r =
      Shell("ulimit -f 64; " + std::string(DUALGRID_EXE) +
            " run scenarios/simple_road.yaml --duration 20 --no-figures -q --out " + dir.string());
  INFO(r.output);
  CHECK(r.code == 1);
  CHECK(CountLines(r.output) == 1);
  CHECK(r.output.find("cannot write " + (dir / "ground_truth.csv").string()) != std::string::npos);
  CHECK(r.output.find("File too large") != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "summary.json"));  // the run does not look finished
}

TEST_CASE("Outputs failing on the output worker say the same on one thread as on two",
          "[cli][newcomer]") {
  // 64 KiB per file (sh counts 512-byte blocks): the pictures and the recording's frames do not
  // fit (warnings, exit 0); in the longer run ground_truth.csv does not either (an error, exit
  // 1). With --threads 1 the
  // recording and the pictures are written in line, with 2 by the output worker: the same lines
  // in the same order, the same warnings in summary.json, and no summary.json after the error.
  for (const int seconds : {2, 4}) {
    std::string said[2];
    std::string warnings[2];
    for (const int threads : {1, 2}) {
      const auto dir =
          TempDir("worker_fails_" + std::to_string(seconds) + "_" + std::to_string(threads));
      const Result r = Shell("ulimit -f 128; " + std::string(DUALGRID_EXE) +
                             " run scenarios/simple_road.yaml --duration " +
                             std::to_string(seconds) + " --snapshots 1,1.5 -q --threads " +
                             std::to_string(threads) + " --out " + dir.string());
      INFO(r.output);
      CHECK(r.code == (seconds == 2 ? 0 : 1));
      CHECK(r.output.find("dualgrid: warning: figure " +
                          (dir / "figures" / "grid_t1.00.png").string() + " not drawn") !=
            std::string::npos);
      CHECK(r.output.find("dualgrid: warning: replay recording ") != std::string::npos);
      said[threads - 1] = std::regex_replace(r.output, std::regex(dir.string()), "DIR");
      if (seconds == 2) {
        const auto listed = nlohmann::json::parse(Slurp(dir / "summary.json")).at("warnings");
        CHECK(listed.size() >= 10);
        warnings[threads - 1] = std::regex_replace(listed.dump(), std::regex(dir.string()), "DIR");
      } else {
        CHECK(r.output.find("dualgrid: error: cannot write " + (dir / "ground_truth.csv").string() +
                            ": File too large") != std::string::npos);
        CHECK_FALSE(fs::exists(dir / "summary.json"));
      }
    }
    CHECK(said[0] == said[1]);
    CHECK(warnings[0] == warnings[1]);
  }
}

TEST_CASE("Every file a run and an experiment write is documented", "[cli][newcomer]") {
  const auto dir = TempDir("outputs");
  REQUIRE(Run("experiment scenarios/simple_road.yaml --seeds 1 --duration 2 --snapshots 1 "
              "--detections csv.gz --write-particles -q --out " +
              dir.string())
              .code == 0);
  const std::string doc = Slurp("docs/output.md");
  // Concrete names are documented as patterns: times as <time>, modes as <mode>, seeds as <n>.
  const std::regex time_re("_t[0-9]+\\.[0-9]+"), mode_re("_(position|velocity|dual)_"),
      seed_re("seed_[0-9]+");
  int files = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    ++files;
    std::string name = fs::relative(e.path(), dir).string();
    name = std::regex_replace(name, seed_re, "seed_<n>");
    name = std::regex_replace(name, std::regex("^seeds/seed_<n>/"), "");
    name = std::regex_replace(name, time_re, "_t<time>");
    name = std::regex_replace(name, mode_re, "_<mode>_");
    INFO(e.path());
    CHECK(doc.find("`" + name + "`") != std::string::npos);
  }
  CHECK(files > 20);
}

TEST_CASE("The paper is cited so that a reader can find it", "[docs][newcomer]") {
  const std::string doc = Slurp("docs/algorithm.md");
  CHECK(doc.find("/work/") == std::string::npos);
  CHECK(doc.find("arXiv:2303.11390") != std::string::npos);
}
