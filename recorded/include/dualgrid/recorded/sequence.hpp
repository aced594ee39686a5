// A recorded radar sequence in memory (docs/recorded-data.md): scans, each of one sensor at its
// own timestamp with the ego's pose from odometry, as the readers of this library fill it (a
// RadarScenes sequence, a dualgrid run folder) and as cosim::RecordedSource steps through it.
// Data only: no SUMO, no files.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "dualgrid/core/types.hpp"
#include "dualgrid/radar_model/sensor_params.hpp"

namespace dualgrid::recorded {

/// One detection of a recorded scan. Positions in the sequence's (world) frame.
struct RecordedPoint {
  double range = 0.0;         ///< [m], sensor frame
  double azimuth = 0.0;       ///< [rad], sensor frame
  double range_rate = 0.0;    ///< vr: uncompensated [m/s]
  double radial_speed = 0.0;  ///< vr_compensated: over ground, along the line of sight [m/s]
  double rcs = 0.0;           ///< [dBsm]
  Position position = Position::Zero();  ///< x_seq, y_seq [m]
  int label = -1;                        ///< RadarScenes label_id (0-11), -1 unlabelled
  int track = -1;                        ///< index into RecordedSequence::track_names, -1 none
};

/// One sensor's scan: its detections and the ego's state at its timestamp.
struct RecordedScan {
  std::int64_t timestamp_us = 0;   ///< sequence clock [us]
  int sensor = 0;                  ///< index into RecordedSequence::sensors
  std::size_t begin = 0, end = 0;  ///< its detections: RecordedSequence::points[begin, end)
  Pose2 ego_pose;                  ///< the ego's box centre and heading, world frame [m, rad]
  Velocity ego_velocity = Velocity::Zero();  ///< of the box centre [m/s]
  double ego_yaw_rate = 0.0;                 ///< [rad/s]
  double lane_yaw = 0.0;  ///< the road's direction [rad]: the heading unless the data say
  /// Its reference objects (annotated data): RecordedSequence::references[ref_begin, ref_end).
  std::size_t ref_begin = 0, ref_end = 0;
};

/// A reference object given by the data set (nuScenes' annotated box, interpolated by the
/// reader to a scan's time), world frame.
struct ReferenceObject {
  std::string id;                        ///< instance token
  std::string type;                      ///< category (vehicle.car, ...)
  OrientedBox box;                       ///< centre [m], yaw [rad], length and width [m]
  Velocity velocity = Velocity::Zero();  ///< over ground [m/s]
};

/// A recorded sequence, validated by its reader: scans in non-decreasing time, every point index
/// inside `points`, every point finite.
struct RecordedSequence {
  std::string name;
  /// The radars, mounted relative to the ego's box centre (x forward, y left).
  std::vector<radar::SensorParams> sensors;
  double ego_length = 4.9;  ///< [m]
  double ego_width = 1.9;   ///< [m]
  std::vector<RecordedScan> scans;
  std::vector<RecordedPoint> points;
  std::vector<std::string> track_names;
  /// The data carry labels (label_id): point-level scores are possible.
  bool has_labels = false;
  /// t = (timestamp_us - time_origin_us) / 1e6 [s]: a whole second at or before the first scan.
  std::int64_t time_origin_us = 0;
  /// Detections dropped by the reader (NaN position or velocity), for the run's notes.
  std::size_t skipped_points = 0;
  /// The data set's own reference objects (per scan, sorted by id). When `annotated`, a cycle's
  /// vehicles are its first scan's references, not boxes estimated from track points.
  bool annotated = false;
  std::vector<ReferenceObject> references;

  double Time(std::int64_t timestamp_us) const {
    return static_cast<double>(timestamp_us - time_origin_us) / 1e6;
  }
};

/// The ego's size every recorded reader accepts (sensors.json, dualgrid.json, a run folder's
/// scans.csv): the ranges of a scenario's vehicle types (sim/scenario.cpp), length in (0, 30] m and
/// width in (0, 4] m. Returns "" when valid, else what was expected, for the reader's message.
inline constexpr double kMaxEgoLength = 30.0;  ///< [m]
inline constexpr double kMaxEgoWidth = 4.0;    ///< [m]
inline std::string EgoSizeError(double length, double width) {
  if (!(length > 0.0 && length <= kMaxEgoLength))
    return "length " + std::to_string(length) + ": expected in (0, 30] m";
  if (!(width > 0.0 && width <= kMaxEgoWidth))
    return "width " + std::to_string(width) + ": expected in (0, 4] m";
  return "";
}

/// Labels 0-10 are road users that move (RadarScenes' dynamic classes); 11 is static.
inline constexpr int kStaticLabel = 11;
inline bool IsMovingLabel(int label) { return label >= 0 && label < kStaticLabel; }

}  // namespace dualgrid::recorded
