// The checked reader of users' files (core/input_file.hpp, core/json_input.hpp): what is not a
// regular file is refused by name before anything can block, sizes and lines are bounded, a
// signal stops a long read, JSON with a key given twice or nested without bound is refused.
#include <catch2/catch.hpp>

#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "dualgrid/core/input_file.hpp"
#include "dualgrid/core/json_input.hpp"

using namespace dualgrid;
namespace fs = std::filesystem;

namespace {

// A fresh folder under the temporary directory, removed at the end of the test.
struct TempDir {
  fs::path dir;
  TempDir() {
    std::string templ = (fs::temp_directory_path() / "dualgrid_input_XXXXXX").string();
    dir = mkdtemp(templ.data());
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  fs::path Write(const std::string& name, const std::string& text) const {
    std::ofstream(dir / name, std::ios::binary) << text;
    return dir / name;
  }
};

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST_CASE("What is not a regular file is refused by name before it is opened", "[core][input]") {
  const TempDir t;
  REQUIRE(mkfifo((t.dir / "fifo").c_str(), 0600) == 0);
  fs::create_directory(t.dir / "folder");
  fs::create_symlink("loop", t.dir / "loop");
  fs::create_symlink("nowhere", t.dir / "dangling");
  const struct {
    fs::path path;
    std::string reason;
  } cases[] = {{t.dir / "fifo", "test input is a FIFO (named pipe), expected a regular file"},
               {t.dir / "folder", "test input is a directory, expected a regular file"},
               {"/dev/zero", "test input is a device, expected a regular file"},
               {t.dir / "loop", "test input is a symbolic link loop"},
               {t.dir / "dangling", "test input is a dangling symbolic link"},
               {t.dir / "absent", "test input not found"}};
  for (const auto& c : cases) {
    INFO(c.path);
    const std::string expected = c.path.string() + ": " + c.reason;
    CHECK_THAT(ErrorOf([&] { ReadInputText(c.path, "test input"); }), Catch::StartsWith(expected));
    CHECK_THAT(ErrorOf([&] { CheckInputFile(c.path, "test input"); }), Catch::StartsWith(expected));
    CHECK(InputExists(c.path) == (c.reason != "test input not found"));
  }
  CHECK_THAT(ErrorOf([&] { CheckInputFolder(t.dir / "fifo", "test folder"); }),
             Catch::Contains("test folder is a FIFO (named pipe), expected a folder"));
  CHECK_NOTHROW(CheckInputFolder(t.dir, "test folder"));
  CHECK(CheckInputFile(t.Write("five", "12345"), "test input") == 5);
}

TEST_CASE("Sizes and lines are bounded, and the bound is named", "[core][input]") {
  const TempDir t;
  const fs::path big = t.Write("big", std::string(5000, 'x'));
  CHECK_THAT(ErrorOf([&] { ReadInputText(big, "test input", 4096); }),
             Catch::Contains("is larger than 4096 bytes"));
  CHECK(ReadInputText(big, "test input", 5000).size() == 5000);
  // A line longer than the cap ends the read early, whatever follows.
  InputStream in(big, "test input");
  std::string line;
  CHECK_THAT(ErrorOf([&] { in.ReadLine(&line, 1000); }),
             Catch::Contains("has a line longer than 1000 bytes"));
  // Lines: '\n' and '\r\n' ends, a last line without an end, empty lines kept.
  InputStream lines(t.Write("lines", "a,b\r\n\nlast"), "test input");
  std::vector<std::string> got;
  while (lines.ReadLine(&line)) got.push_back(line);
  CHECK(got == std::vector<std::string>{"a,b", "", "last"});
}

TEST_CASE("gzip is read by content, damaged gzip is named", "[core][input]") {
  const TempDir t;
  const fs::path gz = t.dir / "data.csv.gz";
  gzFile f = gzopen(gz.c_str(), "wb");
  REQUIRE(f != nullptr);
  const std::string text = "x,y\n1,2\n";
  gzwrite(f, text.data(), static_cast<unsigned>(text.size()));
  gzclose(f);
  CHECK(ReadInputText(gz, "test input") == text);
  // Truncated inside the stream (with or without bytes after): an error, not a short file read
  // as complete.
  std::string raw;
  {
    std::ifstream in(gz, std::ios::binary);
    raw.assign(std::istreambuf_iterator<char>(in), {});
  }
  for (const std::string& tail : {std::string(), std::string(8, '\x55')}) {
    const fs::path cut = t.Write("cut.gz", raw.substr(0, raw.size() / 2) + tail);
    CHECK_THAT(ErrorOf([&] { ReadInputText(cut, "test input"); }),
               Catch::Contains("test input cannot be read (damaged gzip data"));
  }
}

TEST_CASE("A stop signal ends a long read, not a short one", "[core][input]") {
  const TempDir t;
  const fs::path small = t.Write("small", std::string(1 << 18, 'x'));
  const fs::path big = t.Write("big", std::string(std::size_t{17} << 20, 'x'));
  volatile std::sig_atomic_t flag = 0;
  SetInputStopFlag(&flag);
  CHECK(ReadInputText(big, "test input").size() == (std::size_t{17} << 20));
  flag = SIGTERM;
  CHECK(ReadInputText(small, "test input").size() == (1u << 18));  // under 16 MiB: finishes
  CHECK_THROWS_AS(ReadInputText(big, "test input"), InputStopped);
  SetInputStopFlag(nullptr);
  CHECK(ReadInputText(big, "test input").size() == (std::size_t{17} << 20));
}

TEST_CASE("JSON from a file: a key given twice, deep nesting and bad text are named",
          "[core][input][json]") {
  CHECK(ParseJsonInput(R"({"a": {"b": 1, "c": [{"b": 2}, {"b": 3}]}})", "f.json")["a"]["b"] == 1);
  CHECK_THAT(ErrorOf([] { ParseJsonInput(R"({"a": 1, "a": 2})", "f.json"); }),
             Catch::Equals("f.json: key 'a' given twice"));
  CHECK_THAT(
      ErrorOf([] { ParseJsonInput(R"({"s": {"1": {}, "2": {"x": 1, "x": 1}}})", "f.json"); }),
      Catch::Equals("f.json: key 's.2.x' given twice"));
  CHECK_THAT(ErrorOf([] { ParseJsonInput(R"({"l": [{"k": 1, "k": 2}]})", "f.json"); }),
             Catch::Equals("f.json: key 'l[].k' given twice"));
  CHECK_THAT(ErrorOf([] { ParseJsonInput(std::string(100, '[') + std::string(100, ']'), "f"); }),
             Catch::Contains("nested more than 64 deep"));
  CHECK_THAT(ErrorOf([] { ParseJsonInput(R"({"a": )", "f.json"); }),
             Catch::StartsWith("f.json: not valid JSON (at byte"));
  // A type error the reader's own checks missed still names the file.
  const TempDir t;
  const fs::path file = t.Write("t.json", R"({"n": "text"})");
  CHECK_THAT(ErrorOf([&] {
               ReadingJsonInput(file, "test input",
                                [&] { return ReadJsonInput(file, "test input")["n"].get<int>(); });
             }),
             Catch::StartsWith(file.string() + ": test input holds a value of an unexpected type"));
}
