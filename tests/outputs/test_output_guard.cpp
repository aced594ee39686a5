// The output guard (outputs/output_guard.hpp): outputs apart from inputs however the paths are
// spelled, names confined to the output folder, and folders emptied only of dualgrid's own files.
#include <sys/stat.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "dualgrid/outputs/output_guard.hpp"

namespace fs = std::filesystem;
using namespace dualgrid::outputs;

namespace {

fs::path FreshDir(const std::string& name) {
  const fs::path d =
      fs::temp_directory_path() / ("dualgrid_guard_" + std::to_string(getpid()) + "_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void Touch(const fs::path& p, const std::string& text = "x") {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

std::string Slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Every file under `dir` with its content: a digest of the tree.
std::map<std::string, std::string> Tree(const fs::path& dir) {
  std::map<std::string, std::string> t;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    t[fs::relative(e.path(), dir).string()] = e.is_regular_file() ? Slurp(e.path()) : "<dir>";
  return t;
}

bool Refused(const fs::path& out, const fs::path& input) {
  InputSet in;
  in.Add(input, "input");
  try {
    CheckOutputApart(out, in);
    return false;
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    CHECK(what.find("--out") != std::string::npos);  // names the option and both paths
    CHECK(what.find(input.string()) != std::string::npos);
    CHECK(what.find(out.string()) != std::string::npos);
    return true;
  }
}

// `p` spelled another way: relative to the working folder, with `.` and `x/..` detours, or with
// a trailing separator; all name the same place.
fs::path Respell(const fs::path& p, std::mt19937& rng) {
  switch (rng() % 4) {
    case 0:
      return fs::relative(p, fs::current_path());
    case 1: {
      fs::path q = p.parent_path() / "." / p.filename();
      return q;
    }
    case 2:
      return p.parent_path() / "detour" / ".." / p.filename();
    default:
      return fs::path(p.string() + "/");
  }
}

}  // namespace

TEST_CASE("An output equal to, containing or inside an input is refused, however spelled",
          "[outputs][guard]") {
  const fs::path root = FreshDir("apart");
  fs::create_directories(root / "detour");
  std::mt19937 rng(42);
  // Random nested folders a/b/c...; the input and the output are two of them (or unrelated).
  for (int trial = 0; trial < 300; ++trial) {
    auto random_path = [&] {
      fs::path p = root;
      const int depth = 1 + static_cast<int>(rng() % 4);
      for (int k = 0; k < depth; ++k) p /= std::string(1, static_cast<char>('a' + rng() % 3));
      return p;
    };
    const fs::path input = random_path(), out = random_path();
    if (rng() % 2) fs::create_directories(input);  // existing or not: both are compared
    if (rng() % 3 == 0) fs::create_directories(out);
    const std::string i = input.string() + "/", o = out.string() + "/";
    const bool overlap = i.rfind(o, 0) == 0 || o.rfind(i, 0) == 0;
    INFO("input " << input << ", out " << out);
    CHECK(Refused(Respell(out, rng), Respell(input, rng)) == overlap);
  }
}

TEST_CASE("A symbolic link does not hide an overlap", "[outputs][guard]") {
  const fs::path root = FreshDir("links");
  Touch(root / "data" / "run" / "scans.csv");
  fs::create_directory_symlink(root / "data" / "run", root / "alias");
  fs::create_directory_symlink(root / "data", root / "parent_alias");
  CHECK(Refused(root / "alias", root / "data" / "run"));          // the same folder
  CHECK(Refused(root / "alias" / "new", root / "data" / "run"));  // inside it
  CHECK(Refused(root / "parent_alias", root / "data" / "run"));   // contains it
  CHECK(Refused(root / "data" / "run", root / "alias"));          // the input is the link
  CHECK_FALSE(Refused(root / "elsewhere", root / "alias"));
  // A file input: the output may not be the file itself, nor a folder holding it.
  CHECK(Refused(root / "alias" / "scans.csv", root / "data" / "run" / "scans.csv"));
  CHECK(Refused(root / "data", root / "alias" / "scans.csv"));
  CHECK_FALSE(Refused(root / "data" / "other", root / "alias" / "scans.csv"));
}

TEST_CASE("A name never leaves the output folder", "[outputs][guard]") {
  for (const std::string& bad :
       {std::string(), std::string("."), std::string(".."), std::string("../x"), std::string("a/b"),
        std::string("/etc"), std::string("x/"), std::string("a\nb"), std::string("a\0b", 3),
        std::string("tab\there"), std::string(256, 'n')}) {
    INFO("name '" << bad << "'");
    CHECK_THROWS_AS(SafeName(bad, "--sequence"), std::invalid_argument);
  }
  try {
    SafeName("../../X", "--sequence");
  } catch (const std::invalid_argument& e) {
    CHECK(std::string(e.what()).find("--sequence: '../../X'") == 0);
  }
  // Whatever plain name is accepted stays one level below the folder.
  std::mt19937 rng(7);
  const std::string alphabet = "abcXYZ019._- ~'\"$*?[]\\";
  for (int trial = 0; trial < 500; ++trial) {
    std::string name;
    const std::size_t n = 1 + rng() % 12;
    for (std::size_t k = 0; k < n; ++k) name += alphabet[rng() % alphabet.size()];
    if (name == "." || name == "..") continue;
    CHECK(SafeName(name, "name") == name);
    const fs::path joined = (fs::path("/out") / name).lexically_normal();
    CHECK(joined.parent_path() == fs::path("/out"));
  }
}

TEST_CASE("A folder is emptied only with --force, and only of dualgrid's own files",
          "[outputs][guard]") {
  const fs::path root = FreshDir("prepare");
  SECTION("a new folder is created and marked first") {
    PrepareOutputFolder(root / "new" / "run");
    CHECK(fs::is_regular_file(root / "new" / "run" / kRunMarker));
  }
  SECTION("an empty folder is used as it is") {
    fs::create_directories(root / "empty");
    PrepareOutputFolder(root / "empty");
    CHECK(fs::is_regular_file(root / "empty" / kRunMarker));
  }
  SECTION("a folder that is not empty is left alone without --force") {
    Touch(root / "thesis" / "thesis.tex", "precious");
    const auto before = Tree(root / "thesis");
    CHECK_THROWS_WITH(PrepareOutputFolder(root / "thesis"),
                      Catch::Contains("is not empty") && Catch::Contains("thesis.tex"));
    CHECK_THROWS_WITH(PrepareOutputFolder(root / "thesis", {.force = true}),
                      Catch::Contains("not a dualgrid output"));
    CHECK(Tree(root / "thesis") == before);
  }
  SECTION("an earlier output: refused without --force, replaced with it, foreign files kept") {
    const fs::path out = root / "run";
    PrepareOutputFolder(out);
    Touch(out / "table.md");
    Touch(out / "a_file_of_a_new_version.csv");  // not a known name: listed by the seal
    Touch(out / "figures" / "grid.png");
    SealOutputFolder(out);
    Touch(out / "summary.json");
    Touch(out / "my_notes.txt", "mine");  // the user's, after the run
    Touch(root / "outside" / "keep.csv", "keep");
    fs::create_directory_symlink(root / "outside", out / "data");  // ours by name: the link goes
    CHECK_THROWS_WITH(PrepareOutputFolder(out), Catch::Contains("add --force"));
    CHECK(fs::exists(out / "summary.json"));
    PrepareOutputFolder(out, {.force = true});
    CHECK_FALSE(fs::exists(out / "summary.json"));
    CHECK_FALSE(fs::exists(out / "table.md"));
    CHECK_FALSE(fs::exists(out / "a_file_of_a_new_version.csv"));
    CHECK_FALSE(fs::exists(out / "figures"));
    CHECK_FALSE(fs::exists(fs::symlink_status(out / "data")));
    CHECK(Slurp(root / "outside" / "keep.csv") == "keep");  // never what a link points to
    CHECK(Slurp(out / "my_notes.txt") == "mine");
    // The kept file stays kept by the next --force, even once this run is sealed.
    SealOutputFolder(out);
    PrepareOutputFolder(out, {.force = true});
    CHECK(Slurp(out / "my_notes.txt") == "mine");
  }
  SECTION("an output that did not finish: its known names and nested outputs go") {
    const fs::path out = root / "killed";
    PrepareOutputFolder(out);
    Touch(out / "ground_truth.csv");
    Touch(out / "sumo.log");
    PrepareOutputFolder(out / "seeds" / "seed_1");
    PrepareOutputFolder(out / "case_a");  // a nested dualgrid output under another name
    Touch(out / "case_a" / "table.md");
    Touch(out / "unrelated.dat", "keep");
    PrepareOutputFolder(out, {.force = true});
    CHECK(Tree(out).size() == 2);  // the marker and unrelated.dat
    CHECK(Slurp(out / "unrelated.dat") == "keep");
  }
  SECTION("a damaged marker can only make --force remove less") {
    const fs::path out = root / "damaged";
    PrepareOutputFolder(out);
    std::ofstream(out / kRunMarker) << "ours 2e2e\nours zz\nours 2f6574632f706173737764\ngarbage";
    Touch(out / "precious.txt", "keep");
    Touch(out / "table.md");
    PrepareOutputFolder(out, {.force = true});
    CHECK(Slurp(out / "precious.txt") == "keep");
    CHECK_FALSE(fs::exists(out / "table.md"));
    CHECK(fs::exists(root / "damaged"));
  }
  SECTION("a marker that is no regular file is never read through and removes nothing foreign") {
    // The marker is read back under --force: a FIFO would block open(), /dev/zero would never
    // end, a folder or a loop would fail to read. Each must end at once (the checked opener) and
    // leave the folder's foreign files alone.
    for (const std::string kind : {"fifo", "folder", "zero", "loop"}) {
      const fs::path out = root / ("odd_" + kind);
      PrepareOutputFolder(out);
      fs::remove(out / kRunMarker);
      if (kind == "fifo") REQUIRE(mkfifo((out / kRunMarker).c_str(), 0600) == 0);
      if (kind == "folder") fs::create_directory(out / kRunMarker);
      if (kind == "zero") fs::create_symlink("/dev/zero", out / kRunMarker);
      if (kind == "loop") fs::create_symlink(out / kRunMarker, out / kRunMarker);
      Touch(out / "precious.txt", "keep");
      try {
        PrepareOutputFolder(out, {.force = true});
      } catch (const std::invalid_argument&) {
        // refused: as good as removing nothing
      }
      CHECK(Slurp(out / "precious.txt") == "keep");
    }
  }
  SECTION("a file where the folder should be is refused") {
    Touch(root / "afile", "keep");
    CHECK_THROWS_WITH(PrepareOutputFolder(root / "afile", {.force = true}),
                      Catch::Contains("not a folder"));
    CHECK(Slurp(root / "afile") == "keep");
  }
}

TEST_CASE("A scenario's files are inputs", "[outputs][guard]") {
  dualgrid::scenario::ScenarioConfig config;
  config.file = "/data/scen/s.yaml";
  config.sim.network = "highway";
  config.sim.route_files = {"/data/routes/r.rou.xml"};
  config.sim.additional_files = {"/data/add/a.add.xml"};
  InputSet in;
  in.AddScenario(config, "/nets");
  std::set<std::string> paths;
  for (const auto& i : in.inputs()) paths.insert(i.path.string());
  CHECK(paths == std::set<std::string>{"/data/scen/s.yaml", "/nets/highway.net.xml",
                                       "/data/routes/r.rou.xml", "/data/add/a.add.xml"});
  CHECK_THROWS_WITH(CheckOutputApart("/data/routes", in), Catch::Contains("SUMO route file"));
  CHECK_THROWS_AS(CheckOutputApart("/nets", in), std::invalid_argument);
  CHECK_NOTHROW(CheckOutputApart("/data/run", in));
}
