// Scenario files (YAML) -> parameter structs. The loader only fills structs and asks each struct
// to validate itself; the libraries never see YAML.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>

#include "dualgrid/sim/scenario.hpp"

namespace dualgrid::scenario {

/// A malformed scenario: the message names the file, the key and what was expected.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ScenarioConfig {
  std::filesystem::path file;
  sim::ScenarioSpec sim;
};

/// Loads and validates a scenario file. Throws ConfigError.
ScenarioConfig LoadScenario(const std::filesystem::path& file);

}  // namespace dualgrid::scenario
