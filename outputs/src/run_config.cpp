#include "dualgrid/outputs/run_config.hpp"

#include <iostream>
#include <sstream>
#include <stdexcept>

#include "dualgrid/core/input_file.hpp"
#include "dualgrid/outputs/output_file.hpp"

namespace dualgrid::outputs {

scenario::ScenarioConfig LoadRunConfig(const std::filesystem::path& scenario,
                                       const std::vector<std::string>& sets,
                                       std::optional<std::uint64_t> seed,
                                       std::optional<double> duration,
                                       std::optional<double> begin) {
  std::vector<scenario::Override> overrides;
  for (const std::string& text : sets) overrides.push_back(scenario::ParseOverride(text));
  scenario::ScenarioConfig config = scenario::LoadScenario(scenario, overrides);
  config.overrides = sets;
  for (const std::string& w : config.sim.warnings) std::cerr << "dualgrid: warning: " << w << "\n";
  if (seed) config.sim.seed = *seed;
  if (duration) config.sim.duration = *duration;
  if (begin) {
    config.sim.begin = *begin;
    config.sim.begin_source = "command line";
  }
  // The overrides go through the same validation as the file.
  std::string error;
  if (!config.sim.IsValid(&error))
    throw std::invalid_argument(config.file.string() +
                                " with the command-line overrides: " + error);
  return config;
}

void CopyScenario(const scenario::ScenarioConfig& config, const std::filesystem::path& out) {
  // Read again through the checked reader: the file may have changed since it was loaded.
  const std::string text = ReadInputText(config.file, "scenario file");
  std::ostringstream copy;
  copy << "# Copy of " << config.file.string() << " as used for this run; command-line overrides:\n"
       << "#   seed: " << config.sim.seed << ", duration: " << config.sim.duration
       << " s, begin: " << config.sim.begin << " s (SUMO time; " << config.sim.begin_source
       << ")\n";
  for (const std::string& set : config.overrides) copy << "#   --set " << set << "\n";
  copy << "# network as resolved: " << config.sim.network << "\n" << text;
  WriteTextFile(out / "scenario.yaml", copy.str());
}

nlohmann::json ConfigJson(const scenario::ScenarioConfig& config,
                          const std::vector<std::string>& modes) {
  nlohmann::json j = scenario::ConfigToJson(config);
  j["modes"] = modes;
  return j;
}

}  // namespace dualgrid::outputs
