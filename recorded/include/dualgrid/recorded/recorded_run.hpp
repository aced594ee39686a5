// What `dualgrid filter` and Python's run_recorded share: reading an input folder (a RadarScenes
// sequence or a dualgrid run folder). cosim::FitConfig fits a configuration to the sequence.
#pragma once

#include <filesystem>
#include <optional>

#include "dualgrid/recorded/sequence.hpp"

namespace dualgrid::recorded {

struct RecordedInput {
  RecordedSequence sequence;
  bool radarscenes = false;  ///< else a dualgrid run folder
};

/// Reads `input`: a RadarScenes sequence folder (it has scenes.json; `sensors` or the dataset
/// root's sensors.json) or a run folder recorded with --detections exact. Throws
/// std::invalid_argument naming the file and field of bad input.
RecordedInput ReadRecordedInput(const std::filesystem::path& input,
                                const std::optional<std::filesystem::path>& sensors);

}  // namespace dualgrid::recorded
