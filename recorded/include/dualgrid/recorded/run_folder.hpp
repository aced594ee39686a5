// A dualgrid `sim` or `run` folder recorded with `--detections exact` (detections.csv and
// scans.csv, every number with 17 significant digits) read as a RecordedSequence: the
// input of `dualgrid filter RUN_DIR` and of `dualgrid export`.
#pragma once

#include <filesystem>

#include "dualgrid/recorded/sequence.hpp"

namespace dualgrid::recorded {

/// Reads run_dir/scans.csv and run_dir/detections.csv (or .csv.gz). Labels from each source
/// vehicle's vClass (LabelOfVClass), track ids = SUMO vehicle ids; clutter, ghosts and static
/// obstacles are static (label 11) without a track. Throws std::invalid_argument naming the
/// file, the row and the column of bad input, or the missing file.
RecordedSequence ReadRunFolder(const std::filesystem::path& run_dir);

}  // namespace dualgrid::recorded
