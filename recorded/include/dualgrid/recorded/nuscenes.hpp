// nuScenes-layout datasets (docs/recorded-data.md, "nuScenes"): one scene's five radar channels
// read into a RecordedSequence with its annotated vehicles as reference objects, and a
// recorded sequence written as a nuScenes version folder that the public devkit loads.
//
// Read: ROOT/VERSION/*.json (scene, sample, sample_data, calibrated_sensor, sensor, ego_pose,
// sample_annotation, instance, category) and the radar PCD files under ROOT. Every problem of
// the files is a std::invalid_argument of one line naming the file and the field (or record
// token, header key, point).
// Write: every table the devkit loads, samples/ and sweeps/ PCD files, and dualgrid.json (what
// the schema has no field for: the ego's box, the radars' fields of view and order).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "dualgrid/recorded/sequence.hpp"

namespace dualgrid::recorded {

/// The five radar channels of nuScenes, in the reader's default sensor order.
inline constexpr const char* kNuScenesChannels[] = {
    "RADAR_FRONT", "RADAR_FRONT_LEFT", "RADAR_FRONT_RIGHT", "RADAR_BACK_LEFT", "RADAR_BACK_RIGHT"};

/// nuScenes' ego (a Renault Zoe) when dualgrid.json does not say: 4.084 m x 1.730 m, its box
/// centre 1.385 m ahead of the rear axle (the ego frame's origin) [m].
inline constexpr double kNuScenesEgoLength = 4.084;
inline constexpr double kNuScenesEgoWidth = 1.730;
inline constexpr double kNuScenesRearAxleToCentre = 1.385;

struct NuScenesOptions {
  std::string version = "v1.0-mini";  ///< the version folder under the root
  std::string scene;                  ///< the scene's name or token
  /// The devkit's point filters (RadarPointCloud.from_file): the values kept of invalid_state,
  /// dyn_prop and ambig_state; empty keeps all. Defaults: the devkit's.
  std::vector<int> invalid_states = {0};
  std::vector<int> dynprop_states = {0, 1, 2, 3, 4, 5, 6, 7};
  std::vector<int> ambig_states = {3};
  /// An instance is a moving object (a reference of D, D_v; its points labelled moving) when its
  /// annotated speed reaches this at some annotation [m/s]; else it is static (parked).
  double moving_speed = 1.0;
  /// A point is labelled with a moving instance when it lies in its box grown by this on every
  /// side [m]: radar points scatter about the faces they come from, half of them outside.
  double label_margin = 0.5;
  /// Instances with fewer annotations in the scene are skipped (counted).
  int min_annotations = 2;
  /// Throws std::invalid_argument naming the field.
  void Validate() const;
};

/// One annotation (a key frame's box) of a vehicle instance, in the global (world) frame.
struct NuScenesAnnotation {
  std::string instance;  ///< instance token
  std::string category;  ///< category name (vehicle.car, ...)
  std::int64_t timestamp_us = 0;
  Position center = Position::Zero();
  double yaw = 0.0;                      ///< [rad]
  double length = 0.0, width = 0.0;      ///< [m]
  Velocity velocity = Velocity::Zero();  ///< the devkit's box_velocity [m/s] (NaN if none)
  int num_radar_pts = 0;
  bool moving = false;  ///< its instance is a moving object (NuScenesOptions::moving_speed)
};

struct NuScenesScene {
  RecordedSequence sequence;  ///< annotated: references = the moving instances
  std::string scene_token;
  std::vector<std::string> channels;            ///< per sensor of the sequence
  std::vector<NuScenesAnnotation> annotations;  ///< the vehicle instances used, by time
  std::size_t sample_data = 0;                  ///< radar sample_data read (key frames and sweeps)
  std::size_t filtered_points = 0;              ///< points removed by the devkit's filters
  std::size_t empty_clouds = 0;  ///< clouds whose first point is NaN (the devkit: empty)
  std::size_t moving_instances = 0, static_instances = 0;
  std::size_t skipped_instances = 0;  ///< vehicle instances with too few annotations
  /// The ego's velocity was estimated from its poses (else dualgrid.json's ego_pose keys).
  bool ego_velocity_estimated = true;
  /// The scenario file that travels with a dualgrid export (dualgrid.json), if any.
  std::optional<std::filesystem::path> scenario;
};

/// Reads scene `options.scene` of ROOT/`options.version`. Throws std::invalid_argument.
NuScenesScene ReadNuScenes(const std::filesystem::path& root, const NuScenesOptions& options);

/// The sample (key) frames of an export: annotations of `vehicles` per key frame time.
struct NuScenesKeyFrame {
  std::int64_t timestamp_us = 0;
  std::vector<ReferenceObject> vehicles;  ///< id, box, velocity; type = category name
};

struct NuScenesWriteOptions {
  std::string version = "v1.0-mini";  ///< the version folder
  std::string scene = "scene-0001";   ///< the scene's name
  /// A scenario file copied beside the tables and named in dualgrid.json (the run's settings
  /// travel with the export), or none.
  std::optional<std::filesystem::path> scenario;
  /// Positions and velocities in the PCD files as float64 (the devkit reads either; the
  /// published files have float32, which round the run's values: docs/recorded-data.md).
  bool float64 = false;
};

/// Writes `seq` as one scene of ROOT/options.version: its scans as the five channels'
/// sample_data (the assignment of sensors to the channels' directions with the least summed
/// angle; exactly five sensors needed), `key_frames` as the samples with their annotations (each
/// channel's scan nearest a key frame is its key frame; the others are sweeps of the next
/// sample). Throws std::invalid_argument when the sequence does not fit (not five radars, no key
/// frame) and std::runtime_error naming the file when a write fails.
void WriteNuScenes(const RecordedSequence& seq, const std::vector<NuScenesKeyFrame>& key_frames,
                   const std::filesystem::path& root, const NuScenesWriteOptions& options);

/// nuScenes' category of RadarScenes label `label` (docs/recorded-data.md) and back (-1 for a
/// category that is no vehicle).
std::string CategoryOfLabel(int label);
int LabelOfCategory(const std::string& category);

}  // namespace dualgrid::recorded
