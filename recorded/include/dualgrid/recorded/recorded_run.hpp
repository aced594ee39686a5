// What `dualgrid filter` and Python's run_recorded share: reading an input folder (a RadarScenes
// sequence or a dualgrid run folder) and fitting a scenario configuration to the sequence.
#pragma once

#include <filesystem>
#include <optional>

#include "dualgrid/cosim/recorded_source.hpp"
#include "dualgrid/recorded/nuscenes.hpp"
#include "dualgrid/scenario/loader.hpp"

namespace dualgrid::recorded {

struct RecordedInput {
  cosim::RecordedSequence sequence;
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

/// The configuration of a recorded run without a scenario file: the defaults with a 100 m x 60 m
/// grid (RadarScenes' radars look ahead and to both sides) and filter.cycle 0.05 s.
scenario::ScenarioConfig DefaultRecordedConfig();

/// Fits `config` to `seq`: name, duration (the last cycle's time), step length (the mean cycle,
/// for step-based schedules), no simulated radars; returns the source options for its filter
/// cycle (first_dt = filter.cycle) and `batch_window` [s]. Throws std::invalid_argument for a
/// sequence that spans no time.
cosim::RecordedOptions FitConfig(const cosim::RecordedSequence& seq, double batch_window,
                                 scenario::ScenarioConfig* config);

}  // namespace dualgrid::recorded
