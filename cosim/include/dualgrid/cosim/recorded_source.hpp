// Recorded radar data as a detection source (docs/recorded-data.md): a sequence of scans, each of
// one sensor at its own timestamp with the ego's pose from odometry, as read from a RadarScenes
// sequence or a dualgrid run folder (dualgrid::recorded reads the files; this is data only).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "dualgrid/cosim/detection_source.hpp"

namespace dualgrid::cosim {

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
  /// The data set's own reference objects (nuScenes' annotated boxes, interpolated by the
  /// reader to each scan's time; id = instance token, type = category). When `annotated`, a
  /// cycle's vehicles are its first scan's references, not boxes estimated from track points.
  bool annotated = false;
  std::vector<sim::VehicleState> references;

  double Time(std::int64_t timestamp_us) const {
    return static_cast<double>(timestamp_us - time_origin_us) / 1e6;
  }
};

/// Labels 0-10 are road users that move (RadarScenes' dynamic classes); 11 is static.
inline bool IsMovingLabel(int label) { return label >= 0 && label < kStaticLabel; }

/// Options of a RecordedSource.
struct RecordedOptions {
  /// Scans whose timestamps lie within this window [s] of a step's first scan form one filter
  /// cycle (>= 0; 0: every scan is a cycle of its own unless two share a timestamp).
  double batch_window = 0.001;
  /// Half-width [s] of the window of a track's points that estimates its box and velocity.
  double track_window = 0.25;
  /// The first cycle's dt [s] (later: the time between steps).
  double first_dt = 0.05;
};

/// Steps through a RecordedSequence: each step is a batch of scans (RecordedOptions), at the time
/// of its first scan, with that scan's ego state. The labelled moving tracks become the frame's
/// vehicles (box and velocity estimated from their points: docs/recorded-data.md), so that the
/// tracking scores (D, D_v) apply to them; unlabelled data give no vehicles.
class RecordedSource : public DetectionSource {
 public:
  /// `sequence` must outlive the source.
  RecordedSource(const RecordedSequence& sequence, RecordedOptions options);
  void Start(const std::filesystem::path&, const std::filesystem::path&) override {
    started_ = true;
  }
  bool started() const override { return started_; }
  bool Advance(IdRegistry& ids) override;
  void Scan(IdRegistry& ids, std::vector<radar::Detection>* detections,
            std::vector<int>* scanned) override;
  const sim::Frame& frame() const override { return frame_; }
  const radar::EgoMotion& ego() const override { return ego_; }
  const radar::RadarModel& radar() const override { return radar_; }
  bool has_radar() const override { return true; }
  double first_dt() const override { return first_dt_; }
  const PointLabels& labels() const override { return labels_; }
  bool has_labels() const override { return seq_.has_labels; }
  bool reached_end() const override { return next_ >= seq_.scans.size(); }
  /// A RecordedSource over the same sequence and options (the sequence is shared, not copied;
  /// the twin builds its own per-point indexes).
  std::unique_ptr<DetectionSource> Twin() const override;
  /// Steps (batches of scans) in the whole sequence.
  int StepCount() const { return static_cast<int>(batches_.size()); }
  /// Time of the first and the last step [s].
  double first_time() const;
  double last_time() const;

 private:
  void EstimateTracks(IdRegistry& ids);

  const RecordedSequence& seq_;
  RecordedOptions options_;
  radar::RadarModel radar_;
  std::vector<std::size_t> batches_;  // first scan of each batch, and seq_.scans.size() at the end
  std::vector<std::vector<std::size_t>> track_points_;  // per track: its points, in time order
  std::vector<std::int64_t> point_time_;                // per point: its scan's timestamp
  std::vector<Vector2> point_los_;    // per point: unit line of sight from its sensor (world)
  std::size_t batch_ = 0, next_ = 0;  // current batch; first scan after it
  bool started_ = false;
  bool advanced_ = false;  // Advance() has returned true once
  double first_dt_ = 0.05;
  sim::Frame frame_;
  radar::EgoMotion ego_;
  PointLabels labels_;
};

}  // namespace dualgrid::cosim
