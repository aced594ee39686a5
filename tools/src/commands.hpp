// The dualgrid subcommands. Each takes its parsed options and returns the process exit code;
// errors are thrown and reported in one line by main().
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace dualgrid::tools {

/// Options shared by every command that runs a scenario.
struct RunOptions {
  std::filesystem::path scenario;
  std::filesystem::path out;
  std::optional<std::uint64_t> seed;
  std::optional<double> duration;
  std::filesystem::path network_dir;
  bool quiet = false;
};

int RunSim(const RunOptions& options);

}  // namespace dualgrid::tools
