// The run folder of `dualgrid run` and `dualgrid filter` (docs/output.md): one loop over a
// CoSimulation, whatever its detection source, with the same observers and writers.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "dualgrid/cosim/cosimulation.hpp"

namespace dualgrid::tools {

/// What `filter` adds to a run folder: where its detections came from.
struct RecordedRun {
  nlohmann::json input;    ///< summary.json's `input`: the files, scans, cycles, skips, labels
  bool labels = false;     ///< the data carry labels (point scores and tracks)
  bool annotated = false;  ///< the references are the data set's annotated boxes (nuScenes)
  std::size_t skipped_points = 0;
  std::vector<std::string> notes;  ///< the reader's notes for the table
  /// Annotated data: each reference object's category (objects.csv's last column).
  std::map<std::string, std::string> categories;
};

/// Runs `cosim` to its end and writes the run folder options.run.out: the files while it runs,
/// then metrics, tables, figures, the replay and summary.json. `config` is the run's
/// configuration (cosim's); `recorded_run` is null for the co-simulation. Returns the exit code.
int RunLoop(cosim::CoSimulation& cosim, const scenario::ScenarioConfig& config,
            const FilterRunOptions& options, const RecordedRun* recorded_run);

/// The table notes of a recorded run: the point-level scores per mode, or what cannot be scored
/// without labels, and the skipped detections.
std::vector<std::string> RecordedNotes(const RecordedRun& recorded,
                                       const std::vector<std::string>& modes,
                                       const std::vector<eval::ScenarioMetrics>& metrics);

}  // namespace dualgrid::tools
