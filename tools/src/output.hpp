// File output shared by the commands: CSV writers with documented columns (docs/output.md).
#pragma once

#include <filesystem>
#include <fstream>
#include <string>

#include "commands.hpp"
#include "dualgrid/scenario/loader.hpp"
#include "dualgrid/sim/ground_truth.hpp"
#include "pipeline.hpp"

namespace dualgrid::tools {

/// Formats with a fixed number of decimals.
std::string Fixed(double v, int decimals);

/// Loads the scenario and applies command-line overrides (seed, duration).
scenario::ScenarioConfig LoadConfig(const RunOptions& options);

/// Copies the scenario file into the run folder, with the overrides noted, so a run can be
/// repeated.
void CopyScenario(const scenario::ScenarioConfig& config, const std::filesystem::path& out);

/// ground_truth.csv: one row per vehicle (ego included) per step.
class GroundTruthWriter {
 public:
  explicit GroundTruthWriter(const std::filesystem::path& path);
  void Write(const sim::Frame& frame);

 private:
  std::ofstream out_;
};

/// detections.csv: one row per radar detection per step.
class DetectionWriter {
 public:
  explicit DetectionWriter(const std::filesystem::path& path);
  void Write(const Pipeline& pipeline);

 private:
  std::ofstream out_;
};

/// obstacles.csv: guard-rail vertices and parked boxes.
void WriteObstacles(const sim::ScenarioSpec& spec, const std::filesystem::path& path);

/// Opens a file for writing or throws naming it.
std::ofstream OpenOutput(const std::filesystem::path& path);

}  // namespace dualgrid::tools
