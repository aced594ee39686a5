// What `dualgrid filter` and Python's run_recorded share: reading an input folder (a RadarScenes
// sequence or a dualgrid run folder). cosim::FitConfig fits a configuration to the sequence.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "dualgrid/recorded/nuscenes.hpp"
#include "dualgrid/recorded/sequence.hpp"

namespace dualgrid::recorded {

struct RecordedInput {
  RecordedSequence sequence;
  bool radarscenes = false;  ///< a RadarScenes sequence
  std::string kind = "run";  ///< radarscenes, nuscenes or run
  /// nuScenes only: what the reader counted (its `sequence` is moved into `sequence` above).
  std::optional<NuScenesScene> nuscenes;
  /// The scenario file that travelled with a dualgrid export (RadarScenes:
  /// ROOT/dualgrid_scenario.yaml; nuScenes: named in dualgrid.json), if any.
  std::optional<std::filesystem::path> scenario;
};

/// Reads `input`: with `nuscenes`, scene nuscenes->scene of the nuScenes root `input`; else a
/// RadarScenes sequence folder (it has scenes.json; `sensors` or the dataset root's
/// sensors.json) or a run folder recorded with --detections exact. Throws
/// std::invalid_argument naming the file and field of bad input.
RecordedInput ReadRecordedInput(const std::filesystem::path& input,
                                const std::optional<std::filesystem::path>& sensors,
                                const std::optional<NuScenesOptions>& nuscenes = std::nullopt);

}  // namespace dualgrid::recorded
