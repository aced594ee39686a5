// RadarScenes sequences (Schumann et al. 2021; docs/recorded-data.md) read into and written from
// RecordedSequence, through Debian's libhdf5 (its C API).
//
// Read: a sequence folder (data/sequence_N/) with scenes.json and radar_data.h5, and the
// dataset root's sensors.json (two folders up unless given). Every problem of the files is a
// std::invalid_argument of one line naming the file and the field (or dataset, key, row);
// detections with a NaN position or velocity are skipped and counted (the last detections of
// some published sequences), never a crash.
// Write: a dataset root (sensors.json, sequences.json, data/<name>/{scenes.json,radar_data.h5})
// that the public reader and our own read back; float fields as float64.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "dualgrid/recorded/sequence.hpp"

namespace dualgrid::recorded {

/// Where the ego's box centre lies ahead of the rear axle (RadarScenes' car origin) [m], and the
/// box, when sensors.json does not say (its dualgrid_ego key): an E-class-sized test car, 4.9 m x
/// 1.9 m with the front bumper 3.9 m ahead of the rear axle (the radars sit at x = 3.66-3.86 m).
inline constexpr double kDefaultRearAxleToCentre = 1.45;
inline constexpr double kDefaultEgoLength = 4.9;
inline constexpr double kDefaultEgoWidth = 1.9;

/// Reads a RadarScenes sequence folder. `sensors_json`: sensors.json, default
/// sequence_dir/../../sensors.json. Throws std::invalid_argument (bad or missing input).
RecordedSequence ReadRadarScenes(const std::filesystem::path& sequence_dir,
                                 const std::optional<std::filesystem::path>& sensors_json);

/// Writes `seq` as a RadarScenes dataset root `root` holding one sequence named seq.name, with
/// the ego's rear axle `rear_axle_to_centre` [m] behind its box centre. Scans sharing a
/// timestamp get 1 us apart in sensor order (scenes are keyed by timestamp). Sensors become
/// radar_1.. in order. Throws std::runtime_error naming the file when a write fails.
void WriteRadarScenes(const RecordedSequence& seq, const std::filesystem::path& root,
                      double rear_axle_to_centre);

/// RadarScenes' label_id of a SUMO vClass (docs/recorded-data.md, "Labels").
int LabelOfVClass(const std::string& vclass);

}  // namespace dualgrid::recorded
