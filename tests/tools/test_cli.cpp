// Runs the dualgrid program as a user would and checks its output and errors.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_harness.hpp"

namespace fs = std::filesystem;

using namespace dualgrid::testing;

namespace {

fs::path TempDir(const std::string& name) { return dualgrid::testing::TempDir("cli", name); }

int CountOccurrences(const std::string& text, const std::string& what) {
  int n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// A path of cairo's SVG: its style attribute and its points (M/L coordinates only).
struct SvgPath {
  std::string style;
  std::vector<std::pair<double, double>> points;
};

std::vector<SvgPath> SvgPaths(const std::string& svg) {
  std::vector<SvgPath> out;
  const std::regex path(R"re(<path style="([^"]*)" d="([^"]*)")re");
  const std::regex point(R"re([ML] (-?[0-9.]+) (-?[0-9.]+))re");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), path); it != std::sregex_iterator();
       ++it) {
    SvgPath p{(*it)[1], {}};
    const std::string d = (*it)[2];
    for (auto q = std::sregex_iterator(d.begin(), d.end(), point); q != std::sregex_iterator(); ++q)
      p.points.emplace_back(std::stod((*q)[1]), std::stod((*q)[2]));
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace

TEST_CASE("--help lists the subcommands", "[cli]") {
  const Result r = Run("--help");
  CHECK(r.code == 0);
  // Each subcommand on its own line of the Subcommands section.
  for (const char* name :
       {"\n  sim ", "\n  snapshot ", "\n  run ", "\n  experiment ", "\n  tangential "})
    CHECK(r.output.find(name) != std::string::npos);
}

// The launcher (tools/launcher/launcher.cpp): libgomp prints its settings at load with
// OMP_DISPLAY_ENV; a program that re-executed itself would print them twice, first with libgomp's
// default spin count.
TEST_CASE("dualgrid sets OpenMP's wait policy before the program loads, in one load", "[cli]") {
  const Result r = Shell("OMP_DISPLAY_ENV=VERBOSE " + std::string(DUALGRID_EXE) + " --version");
  REQUIRE(r.code == 0);
  CHECK(CountOccurrences(r.output, "OPENMP DISPLAY ENVIRONMENT BEGIN") == 1);
  CHECK(r.output.find("OMP_WAIT_POLICY = 'PASSIVE'") != std::string::npos);
  CHECK(r.output.find("GOMP_SPINCOUNT = '300'\n") != std::string::npos);
  CHECK(r.output.find("dualgrid 0.") != std::string::npos);
  // A policy the user chose is kept.
  const Result user = Shell("OMP_DISPLAY_ENV=VERBOSE OMP_WAIT_POLICY=ACTIVE " +
                            std::string(DUALGRID_EXE) + " --version");
  REQUIRE(user.code == 0);
  CHECK(CountOccurrences(user.output, "OPENMP DISPLAY ENVIRONMENT BEGIN") == 1);
  CHECK(user.output.find("OMP_WAIT_POLICY = 'ACTIVE'") != std::string::npos);
}

TEST_CASE("Child runs and run lists name the command the user ran", "[cli]") {
  const auto d = TempDir("launcher_list");
  REQUIRE(Run("sweep tangential --set tangential.sensor=front --set tangential.count=1 --seeds 1 "
              "--duration 2 --emit list -q --out " +
              (d / "s").string())
              .code == 0);
  const std::string list = Slurp(d / "s" / "runs.txt");
  REQUIRE(!list.empty());
  const std::string first = list.substr(0, list.find(' '));
  CHECK(fs::equivalent(fs::path(first.front() == '\'' ? first.substr(1, first.size() - 2) : first),
                       fs::path(DUALGRID_EXE)));
}

TEST_CASE("A launcher without its program says so in one line", "[cli]") {
  const auto d = TempDir("launcher_alone");
  fs::copy_file(DUALGRID_EXE, d / "dualgrid");
  const Result r = Shell((d / "dualgrid").string() + " --version");
  CHECK(r.code == 1);
  CHECK(CountLines(r.output) == 1);
  CHECK(r.output.find("cannot find dualgrid-bin in " + d.string()) != std::string::npos);
}

TEST_CASE("A child run whose program cannot be executed says so in the error and its log",
          "[cli]") {
  const auto d = TempDir("child_exec");
  const fs::path program = fs::path(DUALGRID_EXE).parent_path() / "dualgrid-bin";
  const Result r = Shell("DUALGRID_COMMAND=" + (d / "missing").string() + " " + program.string() +
                         " experiment scenarios/simple_road.yaml"
                         " --seeds 1 --duration 1 --no-figures -q --out " +
                         (d / "e").string());
  CHECK(r.code != 0);
  const std::string line = "cannot execute " + (d / "missing").string();
  CHECK(r.output.find(line) != std::string::npos);
  CHECK(Slurp(d / "e" / "seeds" / "seed_1.log").find(line) != std::string::npos);
}

TEST_CASE("Same scenario and seed give identical ground truth; another seed differs", "[cli]") {
  const auto a = TempDir("a"), b = TempDir("b"), c = TempDir("c");
  const std::string common = "sim scenarios/simple_road.yaml --duration 12 -q ";
  REQUIRE(Run(common + "--out " + a.string()).code == 0);
  REQUIRE(Run(common + "--out " + b.string()).code == 0);
  REQUIRE(Run(common + "--seed 7 --out " + c.string()).code == 0);
  const std::string ta = Slurp(a / "ground_truth.csv");
  CHECK(CountLines(ta) > 240 * 4);  // 240 steps, at least the ego, lead, follower, oncoming
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

TEST_CASE("snapshot writes the format its --out names", "[cli]") {
  const auto dir = TempDir("snapshot_vector");
  for (const char* name : {"hw.svg", "hw.pdf"}) {
    const Result r =
        Run("snapshot scenarios/highway.yaml --time 3 -q --out " + (dir / name).string());
    INFO(r.output);
    REQUIRE(r.code == 0);
    const std::string text = Slurp(dir / name);
    CHECK(text.rfind(std::string(name) == "hw.svg" ? "<?xml" : "%PDF-", 0) == 0);
  }
  // Every arrow is motion over ground (docs/output.md): the ego's own velocity arrow starts at its
  // centre and points east along the road, and every vehicle's arrow (black, 0.7 pt) is at least
  // 2.5 ego lengths long (all drive 25-35 m/s, 0.5 s of motion). Arrows of the velocity relative
  // to the ego would give the ego none and the truck alongside a stub.
  const std::vector<SvgPath> paths = SvgPaths(Slurp(dir / "hw.svg"));
  const auto ego = std::find_if(paths.begin(), paths.end(), [](const SvgPath& p) {
    return p.style.find("fill:rgb(30%,78%,30%)") != std::string::npos && p.points.size() >= 4;
  });
  REQUIRE(ego != paths.end());
  double cx = 0.0, cy = 0.0, length = 0.0;
  for (std::size_t i = 0; i < 4; ++i) {
    cx += 0.25 * ego->points[i].first;
    cy += 0.25 * ego->points[i].second;
    const auto& [x1, y1] = ego->points[(i + 1) % 4];
    length = std::max(length, std::hypot(x1 - ego->points[i].first, y1 - ego->points[i].second));
  }
  int arrows = 0, ego_arrows = 0;
  for (const SvgPath& p : paths) {
    if (p.style.find("stroke-width:0.7;") == std::string::npos ||
        p.style.find("stroke:rgb(0%,0%,0%)") == std::string::npos || p.points.size() != 2)
      continue;
    ++arrows;
    const auto [x0, y0] = p.points[0];
    const auto [x1, y1] = p.points[1];
    INFO("arrow from (" << x0 << ", " << y0 << ") to (" << x1 << ", " << y1 << "), ego length "
                        << length);
    CHECK(std::hypot(x1 - x0, y1 - y0) > 2.5 * length);
    if (std::hypot(x0 - cx, y0 - cy) < 0.1 * length) {
      ++ego_arrows;
      CHECK(x1 - x0 > 2.5 * length);
      CHECK(std::abs(y1 - y0) < 0.1 * length);
    }
  }
  CHECK(ego_arrows == 1);
  CHECK(arrows >= 3);  // the ego, the truck alongside and the car overtaking on the right

  const Result bad =
      Run("snapshot scenarios/highway.yaml --time 3 -q --out " + (dir / "hw.jpg").string());
  CHECK(bad.code != 0);
  CHECK(bad.output.find("expected a file name ending in .png, .svg or .pdf") != std::string::npos);
}

TEST_CASE("snapshot writes a bird's-eye PNG", "[cli]") {
  const auto dir = TempDir("snapshot");
  const auto png = dir / "hw.png";
  const Result r = Run("snapshot scenarios/highway.yaml --time 3 -q --out " + png.string());
  INFO(r.output);
  REQUIRE(r.code == 0);
  std::ifstream in(png, std::ios::binary);
  char magic[8] = {};
  in.read(magic, 8);
  CHECK(std::string(magic + 1, 3) == "PNG");
  CHECK(fs::file_size(png) > 10000);
}

TEST_CASE("sim writes detections for all five radars", "[cli]") {
  const auto dir = TempDir("detections");
  REQUIRE(Run("sim scenarios/highway.yaml --duration 2 -q --out " + dir.string()).code == 0);
  const std::string csv = Slurp(dir / "detections.csv");
  for (const char* name :
       {",front_left,", ",front_right,", ",rear_left,", ",rear_right,", ",front,"})
    CHECK(csv.find(name) != std::string::npos);
  CHECK(csv.find(",alongside_truck,") != std::string::npos);  // the parallel truck is seen
}

TEST_CASE("An unknown sensor in a scenario is one line with a non-zero exit", "[cli]") {
  const auto dir = TempDir("sensor");
  std::string text = Slurp("scenarios/simple_road.yaml");
  text += "\nsensors:\n  overrides:\n    roof: {max_range: 100}\n";
  std::ofstream(dir / "s.yaml") << text;
  const Result r = Run("sim " + (dir / "s.yaml").string() + " --out " + (dir / "o").string());
  CHECK(r.code != 0);
  CHECK(CountLines(r.output) == 1);
  CHECK(r.output.find("unknown sensor 'roof'") != std::string::npos);
}

TEST_CASE("run: short end-to-end runs give finite metrics for all three modes", "[cli][run]") {
  const std::string scenario = GENERATE("simple_road", "highway");
  const auto dir = TempDir("run_" + scenario);
  const Result r = Run("run scenarios/" + scenario + ".yaml --duration 6 -q --out " + dir.string());
  INFO(r.output);
  REQUIRE(r.code == 0);
  const std::string metrics = Slurp(dir / "metrics.json");
  for (const char* mode : {"\"position\"", "\"velocity\"", "\"dual\""})
    CHECK(metrics.find(mode) != std::string::npos);
  CHECK(metrics.find("nan") == std::string::npos);
  CHECK(metrics.find("inf") == std::string::npos);
  const std::string table = Slurp(dir / "table.csv");
  CHECK(table.rfind("scenario,metric,unit,mode", 0) == 0);
  CHECK(table.find(",D,") != std::string::npos);
  CHECK(fs::exists(dir / "figures" / "tracked_share.png"));
}

TEST_CASE("run: every output is the same whatever the number of OpenMP threads", "[cli][run]") {
  const auto a = TempDir("threads1"), b = TempDir("threads2"), c = TempDir("threads4");
  // Figures, detections and particles on: every file a run can write is compared. On 2 threads
  // the observers' rows, traces and replay frames are made inside the step's region, by either
  // thread (StepObserver::Prepare); on 4, each filter also runs its own loops on 2.
  const std::string common =
      "run scenarios/highway.yaml --duration 4 --snapshots 2 --detections csv --write-particles "
      "-q ";
  REQUIRE(Run(common + "--threads 1 --out " + a.string()).code == 0);
  REQUIRE(Run(common + "--threads 2 --out " + b.string()).code == 0);
  REQUIRE(Run(common + "--threads 4 --out " + c.string()).code == 0);
  const auto da = nlohmann::json::parse(Slurp(a / "summary.json")).at("digests");
  const auto db = nlohmann::json::parse(Slurp(b / "summary.json")).at("digests");
  const auto dc = nlohmann::json::parse(Slurp(c / "summary.json")).at("digests");
  CHECK(da.size() >= 19);
  CHECK(da == db);
  CHECK(da == dc);
  // The digest is of the bytes: the same files compared directly.
  for (const char* f : {"objects.csv", "detections.csv", "clusters.csv", "ground_truth.csv"}) {
    INFO(f);
    CHECK(Slurp(a / f) == Slurp(b / f));
    CHECK(Slurp(a / f) == Slurp(c / f));
  }
}

TEST_CASE("tangential: crossing traffic shows almost no Doppler to the front radar", "[cli]") {
  const auto dir = TempDir("tangential");
  const auto yaml = dir / "crossing.yaml";
  REQUIRE(Run("tangential --kind crossing --count 2 --speed 15 -q --out " + yaml.string()).code ==
          0);
  REQUIRE(Run("sim " + yaml.string() + " -q --out " + (dir / "run").string()).code == 0);
  std::ifstream in(dir / "run" / "detections.csv");
  std::string line;
  std::getline(in, line);  // header
  int near_axis = 0;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) f.push_back(cell);
    // columns: 3 sensor_name, 9 y_ego, 12 radial_speed, 17 source
    if (f[3] != "front" || f[17].rfind("cross_", 0) != 0) continue;
    if (std::abs(std::stod(f[9])) > 2.0) continue;
    ++near_axis;
    // A crossing car within 2 m of the ego's axis, >= 30 m ahead, moving at 15 m/s across it:
    // radial speed <= 15 * 2 / 30 = 1 m/s, plus range-rate noise (sigma ~0.1 m/s): < 2 m/s.
    CHECK(std::abs(std::stod(f[12])) < 2.0);
  }
  CHECK(near_axis > 20);
}

TEST_CASE("tangential: bad options are rejected", "[cli]") {
  CHECK(Run("tangential --kind diagonal --out /tmp/x.yaml").code != 0);
  const Result r = Run("tangential --kind parallel --spacing 5 --out /tmp/x.yaml");
  CHECK(r.code != 0);
  CHECK(r.output.find("--spacing") != std::string::npos);
}

TEST_CASE("experiment: seeds run in separate processes and aggregate into tables", "[cli][run]") {
  const auto dir = TempDir("experiment");
  const Result r =
      Run("experiment scenarios/simple_road.yaml --seeds 2 --duration 3 -q --out " + dir.string());
  INFO(r.output);
  REQUIRE(r.code == 0);
  for (const char* seed : {"seed_1", "seed_2"})
    CHECK(fs::exists(dir / "seeds" / seed / "metrics.json"));
  const std::string table = Slurp(dir / "table.csv");
  // Two seeds per mode behind each D value.
  CHECK(table.find("simple_road,D,%,dual,2,") != std::string::npos);
  CHECK(fs::exists(dir / "table.md"));
  CHECK(fs::exists(dir / "figures" / "tracked_share.png"));
}

TEST_CASE("experiment forwards the picture options to its runs", "[cli][run]") {
  const auto with = TempDir("exp_fig"), without = TempDir("exp_nofig");
  const std::string common = "experiment scenarios/simple_road.yaml --seeds 1 --duration 2 -q ";
  REQUIRE(Run(common + "--snapshots 1 --out " + with.string()).code == 0);
  CHECK(fs::exists(with / "seeds" / "seed_1" / "figures" / "grid_t1.00.png"));
  CHECK(fs::exists(with / "figures" / "grid_t1.00.png"));
  // Every figure in every format by default, vectors included, in the runs and the experiment.
  for (const char* f : {"grid_t1.00.svg", "grid_t1.00.pdf", "scene_t1.00.pdf"})
    CHECK(fs::exists(with / "seeds" / "seed_1" / "figures" / f));
  CHECK(fs::exists(with / "figures" / "tracked_share_v.svg"));
  // --figure-formats chooses, and is forwarded to the seed that draws.
  const auto png_only = TempDir("exp_png_only");
  REQUIRE(Run(common + "--snapshots 1 --figure-formats png --out " + png_only.string()).code == 0);
  CHECK(fs::exists(png_only / "seeds" / "seed_1" / "figures" / "grid_t1.00.png"));
  CHECK_FALSE(fs::exists(png_only / "seeds" / "seed_1" / "figures" / "grid_t1.00.svg"));
  CHECK_FALSE(fs::exists(png_only / "figures" / "tracked_share.pdf"));
  REQUIRE(Run(common + "--no-figures --out " + without.string()).code == 0);
  CHECK_FALSE(fs::exists(without / "figures" / "tracked_share.png"));
  CHECK(fs::is_empty(without / "seeds" / "seed_1" / "figures"));
  CHECK(Run(common + "--seed 4 --out " + without.string()).code != 0);
}

TEST_CASE("Runs that cannot produce a frame are errors, not empty results", "[cli]") {
  const auto dir = TempDir("noframe");
  // The ego departs after the end.
  std::string text = Slurp("scenarios/simple_road.yaml");
  const auto pos = text.find("  position: 300\n");
  REQUIRE(pos != std::string::npos);
  text.insert(pos, "  depart: 70\n");
  std::ofstream(dir / "late.yaml") << text;
  Result r = Run("run " + (dir / "late.yaml").string() + " -q --out " + (dir / "o").string());
  CHECK(r.code != 0);
  CHECK(r.output.find("ego.depart") != std::string::npos);
  // Shorter than one step.
  r = Run("run scenarios/simple_road.yaml --duration 0.01 -q --out " + (dir / "o2").string());
  CHECK(r.code != 0);
  CHECK(r.output.find("duration") != std::string::npos);
  // A picture before the first step.
  r = Run("snapshot scenarios/simple_road.yaml --time 0.01 -q --out " + (dir / "x.png").string());
  CHECK(r.code != 0);
  CHECK(CountLines(r.output) == 1);
}

namespace {

std::vector<nlohmann::json> AuditRecords(const fs::path& file) {
  std::vector<nlohmann::json> out;
  std::istringstream in(Slurp(file));
  for (std::string line; std::getline(in, line);) out.push_back(nlohmann::json::parse(line));
  return out;
}

// The figure's texts joined by spaces: a phrase of a caption that wrapped is found too.
bool HasText(const nlohmann::json& record, const std::string& part) {
  std::string all;
  for (const auto& s : record.at("strings")) all += s.get<std::string>() + " ";
  return all.find(part) != std::string::npos;
}

}  // namespace

// Issue 15: every figure the program draws is readable at one column (smallest font / width >=
// 7 pt / 3.5 in), its PNG is 300 dpi, and it says what it shows: axes relative to the ego,
// frames of the arrows, what the colours and whiskers mean. The figures report themselves
// through DUALGRID_FIGURE_AUDIT (docs/output.md).
TEST_CASE("Every figure a user gets is readable at one column and says what it shows",
          "[cli][figures]") {
  const auto dir = TempDir("figure_audit");
  const auto audit = dir / "audit.jsonl";
  const std::string env =
      "DUALGRID_FIGURE_AUDIT=" + audit.string() + " " + std::string(DUALGRID_EXE) + " ";
  Result r = Shell(env +
                   "experiment scenarios/highway.yaml --seeds 2 --duration 2 --snapshots 1 "
                   "-q --out " +
                   (dir / "exp").string());
  INFO(r.output);
  REQUIRE(r.code == 0);
  r = Shell(env + "snapshot scenarios/simple_road.yaml --time 2 -q --out " +
            (dir / "snap.pdf").string());
  REQUIRE(r.code == 0);
  r = Shell(env +
            "sweep tangential --set tangential.sensor=front --set tangential.angle=0:90:90 "
            "--set tangential.count=1 --seeds 2 --duration 8 -j 2 -q --out " +
            (dir / "sweep").string());
  REQUIRE(r.code == 0);

  std::map<std::string, std::vector<nlohmann::json>> kinds;
  for (const nlohmann::json& rec : AuditRecords(audit)) {
    const fs::path path = rec.at("path").get<std::string>();
    const std::string name = path.filename().string();
    INFO(name << ": smallest text " << rec.at("min_font") << " of " << rec.at("width"));
    CHECK(rec.at("texts").get<int>() > 5);
    CHECK(rec.at("min_font").get<double>() / rec.at("width").get<double>() >= 7.0 / 252.0);
    if (path.extension() == ".png") CHECK(rec.at("png_scale").get<double>() == Approx(300.0 / 72));
    std::string kind = name.substr(0, name.find('.'));
    if (kind.rfind("grid_t", 0) == 0) kind = "grid";
    if (kind.rfind("scene_t", 0) == 0) kind = "scene";
    if (path.parent_path().parent_path().filename() == "sweep") kind = "sweep";
    if (path.parent_path().parent_path().filename() == "exp") kind = "experiment_" + kind;
    kinds[kind].push_back(rec);
  }
  // Every kind is there, in its three formats (the snapshot in the one it was asked for).
  for (const char* kind : {"grid", "scene", "weights", "tracked_share", "tracked_share_v",
                           "experiment_tracked_share", "experiment_tracked_share_v"}) {
    INFO(kind);
    CHECK(kinds[kind].size() == 3);
  }
  CHECK(kinds["snap"].size() == 1);
  CHECK(kinds["sweep"].size() >= 15);  // five metrics, png + svg + pdf
  const auto all = [&](const std::string& kind, const std::string& text) {
    INFO(kind << " says '" << text << "'");
    REQUIRE_FALSE(kinds[kind].empty());
    for (const auto& rec : kinds[kind]) CHECK(HasText(rec, text));
  };
  for (const char* kind : {"scene", "snap"}) {
    for (const char* text : {"x from the ego [m]", "motion over ground", "front_left", "rear_right",
                             "velocity (0.5 s)", "radial velocity (0.5 s)", "Colour: the radar"})
      all(kind, text);
  }
  for (const char* text : {"position", "velocity", "dual", "x from the ego [m]", "over ground",
                           "white free, black static, grey unknown"})
    all("grid", text);
  for (const char* text :
       {"w_position", "w_velocity", "alongside_truck", "This run uses the radial likelihood"})
    all("weights", text);
  all("tracked_share_v", "One run: no confidence interval");
  all("experiment_tracked_share", "whiskers: 95 % confidence interval");
  all("experiment_tracked_share_v", "alongside_truck");
  // The sweep figure's caption says what is drawn: lines through the means, and (two seeds)
  // error bars.
  all("sweep", "Lines: the mean over the seeds");
  all("sweep", "Error bars: 95 % confidence interval");
}

// The weights figure explains its shares for the likelihood the run used: with the paper preset
// (eq. (8) in its vector form) the explanation is the paper's, not the default's.
TEST_CASE("The weights figure's caption names the run's velocity likelihood", "[cli][figures]") {
  const auto dir = TempDir("figure_audit", "paper_weights");
  const auto audit = dir / "audit.jsonl";
  const Result r =
      Shell("DUALGRID_FIGURE_AUDIT=" + audit.string() + " " + std::string(DUALGRID_EXE) +
            " run scenarios/highway.yaml --duration 2 --snapshots 1 --no-record "
            "--figure-formats svg --set filter.preset=paper -q --out " +
            (dir / "run").string());
  INFO(r.output);
  REQUIRE(r.code == 0);
  int weights = 0;
  for (const nlohmann::json& rec : AuditRecords(audit)) {
    if (fs::path(rec.at("path").get<std::string>()).stem() != "weights") continue;
    ++weights;
    CHECK(HasText(rec, "This run uses eq. (8) in its vector form"));
    CHECK_FALSE(HasText(rec, "This run uses the radial likelihood"));
  }
  CHECK(weights == 1);
}
