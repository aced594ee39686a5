// A run's configuration and the two files that record it in the run folder: scenario.yaml (the
// scenario file as used, with its overrides) and config.json (every parameter as resolved).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dualgrid/scenario/loader.hpp"

namespace dualgrid::outputs {

/// Loads `scenario` with the `sets` overrides ("KEY=VALUE", scenario::ParseOverride, applied in
/// order and kept in config.overrides), then the `seed`, `duration` [s] and `begin` [s, SUMO time]
/// when given (`begin` from here is recorded as coming from the command line). The loader's
/// warnings go to stderr. Throws scenario::ConfigError / std::invalid_argument naming the file and
/// key of bad input, including overrides that break the scenario's validation.
scenario::ScenarioConfig LoadRunConfig(const std::filesystem::path& scenario,
                                       const std::vector<std::string>& sets,
                                       std::optional<std::uint64_t> seed,
                                       std::optional<double> duration,
                                       std::optional<double> begin = std::nullopt);

/// Writes out/scenario.yaml: the scenario file as used, headed by the overrides and the resolved
/// network, so a run can be repeated. Throws std::runtime_error naming the file when a write fails.
void CopyScenario(const scenario::ScenarioConfig& config, const std::filesystem::path& out);

/// config.json's content: every parameter the run used (scenario::ConfigToJson) and `modes`.
nlohmann::json ConfigJson(const scenario::ScenarioConfig& config,
                          const std::vector<std::string>& modes);

}  // namespace dualgrid::outputs
