// summary.json's digests (outputs/run_folder.hpp): which files they cover, their FNV-1a values,
// and digests taken early (FolderDigests, while the figures are drawn) reused only for files
// that have not changed since.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <string>

#include "dualgrid/core/digest.hpp"
#include "dualgrid/outputs/run_folder.hpp"

namespace fs = std::filesystem;
using dualgrid::outputs::FileDigests;
using dualgrid::outputs::FolderDigests;
using dualgrid::outputs::OutputDigests;

namespace {

fs::path Folder(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("dualgrid_test_digests_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir / "figures");
  fs::create_directories(dir / "sumo_outputs");
  return dir;
}

void Write(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  REQUIRE(out.good());
}

std::string Fnv(const std::string& text) {
  dualgrid::Fnv1a64 h;
  h.Add(text);
  return h.Hex();
}

}  // namespace

TEST_CASE("digests cover the run's files, not summary.json, logs or SUMO's outputs", "[digests]") {
  const fs::path dir = Folder("cover");
  Write(dir / "metrics.json", "{}\n");
  Write(dir / "figures" / "a.svg", "<svg/>");
  Write(dir / "summary.json", "{}");
  Write(dir / "sumo.log", "log");
  Write(dir / "sumo_outputs" / "tripinfo.xml", "<x/>");
  const nlohmann::json d = OutputDigests(dir);
  CHECK(d.size() == 2);
  CHECK(d.at("metrics.json") == Fnv("{}\n"));
  CHECK(d.at("figures/a.svg") == Fnv("<svg/>"));
  CHECK(Fnv("a") == "af63dc4c8601ec8c");  // FNV-1a 64's published value for "a"
}

TEST_CASE("digests taken early give the same digests as digests taken at the end", "[digests]") {
  const fs::path dir = Folder("early");
  Write(dir / "frames.bin", std::string(200000, '\x07'));
  Write(dir / "table.md", "| a |\n");
  const FileDigests early = FolderDigests(dir);
  REQUIRE(early.size() == 2);
  CHECK(early.at("table.md").hex == Fnv("| a |\n"));
  CHECK(early.at("table.md").size == 6);
  Write(dir / "figures" / "late.png", "png");  // written after the early digests
  const nlohmann::json d = OutputDigests(dir, early);
  CHECK(d == OutputDigests(dir));
  CHECK(d.at("figures/late.png") == Fnv("png"));
}

TEST_CASE("an early digest is used only while its file's size and time are unchanged",
          "[digests]") {
  const fs::path dir = Folder("changed");
  Write(dir / "a.csv", "1,2\n");
  Write(dir / "b.csv", "3,4\n");
  FileDigests early = FolderDigests(dir);
  // A stand-in digest for a.csv shows that an unchanged file's early digest is taken as it is.
  early.at("a.csv").hex = "0123456789abcdef";
  Write(dir / "b.csv", "3,4,5\n");  // rewritten: another size
  const nlohmann::json d = OutputDigests(dir, early);
  CHECK(d.at("a.csv") == "0123456789abcdef");
  CHECK(d.at("b.csv") == Fnv("3,4,5\n"));
  // The same size, another modification time: read again.
  Write(dir / "a.csv", "9,9\n");
  fs::last_write_time(dir / "a.csv", early.at("a.csv").modified + std::chrono::seconds(5));
  CHECK(OutputDigests(dir, early).at("a.csv") == Fnv("9,9\n"));
}

TEST_CASE("early digests leave out the files being written, which the end digests read",
          "[digests]") {
  const fs::path dir = Folder("skip");
  Write(dir / "table.md", "| a |\n");
  Write(dir / "figures" / "weights.png", "half");  // the output worker is still writing it
  const FileDigests early = FolderDigests(dir, {"figures/weights.png", "figures/absent.svg"});
  CHECK(early.size() == 1);
  CHECK(early.count("table.md") == 1);
  CHECK(early.count("figures/weights.png") == 0);
  // Finished with the same size and (coarse clocks) possibly the same time: still read again.
  Write(dir / "figures" / "weights.png", "done");
  const nlohmann::json d = OutputDigests(dir, early);
  CHECK(d.at("figures/weights.png") == Fnv("done"));
  CHECK(d == OutputDigests(dir));
}
