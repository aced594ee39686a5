// A dualgrid `sim` or `run` folder recorded with `--detections exact` (detections.csv and
// scans.csv, every number with 17 significant digits) read as a RecordedSequence: the
// input of `dualgrid filter RUN_DIR` and of `dualgrid export`.
#pragma once

#include <filesystem>

#include <vector>

#include "dualgrid/recorded/nuscenes.hpp"
#include "dualgrid/recorded/sequence.hpp"

namespace dualgrid::recorded {

/// Reads run_dir/scans.csv and run_dir/detections.csv (or .csv.gz). Labels from each source
/// vehicle's vClass (LabelOfVClass), track ids = SUMO vehicle ids; clutter, ghosts and static
/// obstacles are static (label 11) without a track. Throws std::invalid_argument naming the
/// file, the row and the column of bad input, or the missing file.
RecordedSequence ReadRunFolder(const std::filesystem::path& run_dir);

/// The vehicles (ego excluded) of run_dir/ground_truth.csv at every step whose time is a
/// multiple of `period` [s] (nuScenes' 2 Hz samples: 0.5), as key frames; each vehicle's type is
/// the nuScenes category of its vClass as the detections of `seq` (ReadRunFolder) label it,
/// vehicle.car for one never detected. Throws std::invalid_argument naming the file, row and
/// column of bad input.
std::vector<NuScenesKeyFrame> ReadKeyFrames(const std::filesystem::path& run_dir,
                                            const RecordedSequence& seq, double period);

}  // namespace dualgrid::recorded
