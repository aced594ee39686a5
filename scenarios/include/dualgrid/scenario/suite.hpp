// Regression suites (`dualgrid regress`, docs/regression.md): YAML -> RegressionSuite, and back
// for `--record`. The checks themselves live in eval/regression.hpp.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "dualgrid/eval/regression.hpp"
#include "dualgrid/scenario/loader.hpp"

namespace dualgrid::scenario {

/// One case: a scenario with overrides, run over `seeds` seeds in the listed modes, and the
/// checks on its aggregated table.
struct RegressionCase {
  std::string name;
  /// Absolute (the file gives it relative to the suite); "tangential" for the stress-case
  /// generator, whose options are the `tangential.*` entries of `sets` (as for `dualgrid sweep`).
  std::filesystem::path scenario;
  bool IsGenerator() const { return scenario == "tangential"; }
  std::vector<std::string> sets;  ///< KEY=VALUE overrides, as for --set
  std::vector<std::string> modes = {"position", "velocity", "dual"};
  std::optional<double> duration;  ///< [s], as `--duration` (the scenario's when empty)
  int seeds = 3;
  std::uint64_t first_seed = 1;
  /// Expected digest of seed first_seed's tables, objects and clusters ("" = not recorded).
  std::string digest;
  std::vector<eval::Band> bands;
  std::vector<eval::Ordering> orderings;
  /// Metrics to record bands for with --record (every mode of the case), besides the banded ones.
  std::vector<std::string> record;
};

struct RegressionSuite {
  std::filesystem::path file;
  std::string name;
  std::vector<RegressionCase> cases;
  std::vector<eval::Ordering> orderings;  ///< between cases ("case:mode.metric" on both sides)
};

/// Loads and validates a suite: every scenario exists and loads with its overrides, modes and
/// metrics are known, bands are not inverted, orderings parse and name existing cases and modes.
/// Throws ConfigError (one line: file, key, what was expected).
RegressionSuite LoadSuite(const std::filesystem::path& file);

/// The suite as YAML (scenario paths relative to `relative_to`, the folder of the file written).
std::string SuiteToYaml(const RegressionSuite& suite, const std::filesystem::path& relative_to);

}  // namespace dualgrid::scenario
