// Running the dualgrid program from a test as a user would: its exit code and output, files,
// and fresh scratch folders. Shared by the end-to-end tests of tests/tools/.
#pragma once

#include <sys/wait.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace dualgrid::testing {

namespace fs = std::filesystem;

struct Result {
  int code;            ///< exit code; 128 + signal if killed
  std::string output;  ///< stdout and stderr
};

/// Runs a shell command line; stderr goes with stdout.
inline Result Shell(const std::string& cmd) {
  FILE* pipe = popen((cmd + " 2>&1").c_str(), "r");
  REQUIRE(pipe != nullptr);
  std::string out;
  char buf[4096];
  while (std::size_t n = std::fread(buf, 1, sizeof buf, pipe)) out.append(buf, n);
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), out};
}

/// Runs dualgrid with `args` (a shell word list).
inline Result Run(const std::string& args) { return Shell(std::string(DUALGRID_EXE) + " " + args); }

inline std::string Slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// A new, empty folder under the system's temporary folder, named after the test group.
inline fs::path TempDir(const std::string& group, const std::string& name) {
  const auto d = fs::temp_directory_path() / ("dualgrid_" + group + "_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

inline int CountLines(const std::string& s) {
  return static_cast<int>(std::count(s.begin(), s.end(), '\n'));
}

/// Rows of a CSV file (no quoted commas) as column -> text maps.
inline std::vector<std::map<std::string, std::string>> ReadCsv(const fs::path& path) {
  std::istringstream in(Slurp(path));
  std::string line;
  std::vector<std::string> header;
  std::getline(in, line);
  {
    std::istringstream h(line);
    for (std::string cell; std::getline(h, cell, ',');) header.push_back(cell);
  }
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    std::istringstream r(line);
    std::map<std::string, std::string> row;
    std::size_t i = 0;
    for (std::string cell; std::getline(r, cell, ',') && i < header.size(); ++i)
      row[header[i]] = cell;
    rows.push_back(row);
  }
  return rows;
}

}  // namespace dualgrid::testing
