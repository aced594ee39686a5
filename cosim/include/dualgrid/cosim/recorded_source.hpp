// Recorded radar data as a detection source (docs/recorded-data.md): steps through a
// recorded::RecordedSequence (dualgrid::recorded reads the files), and fits a scenario
// configuration to it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "dualgrid/cosim/detection_source.hpp"
#include "dualgrid/recorded/sequence.hpp"
#include "dualgrid/scenario/loader.hpp"

namespace dualgrid::cosim {

// The sequence types live in dualgrid::recorded (the readers' side, without SUMO); a
// RecordedSource reads them under these names too.
using recorded::IsMovingLabel;
using recorded::RecordedPoint;
using recorded::RecordedScan;
using recorded::RecordedSequence;

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
/// of its first scan, with that scan's ego state. The frame's vehicles, to which the tracking
/// scores (D, D_v) apply: an annotated sequence's references of that scan (nuScenes), else the
/// labelled moving tracks (box and velocity estimated from their points: docs/recorded-data.md);
/// unlabelled data give no vehicles. Steps count from 1, as the co-simulation's.
class RecordedSource : public DetectionSource {
 public:
  /// `sequence` must outlive the source.
  RecordedSource(const RecordedSequence& sequence, RecordedOptions options);
  /// Ready to Advance(): a recorded sequence needs no folders (it is in memory already).
  void Start() { started_ = true; }
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
  /// The interface's Start: no folder is used (Start()).
  void Start(const SourceFolders&) override { Start(); }
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

/// The configuration of a recorded run without a scenario file: the defaults with a 100 m x 60 m
/// grid (RadarScenes' radars look ahead and to both sides) and filter.cycle 0.05 s.
scenario::ScenarioConfig DefaultRecordedConfig();

/// Fits `config` to `seq`: name, duration (the last cycle's time), step length (the mean cycle,
/// for step-based schedules), no simulated radars; returns the source options for its filter
/// cycle (first_dt = filter.cycle) and `batch_window` [s]. Throws std::invalid_argument for a
/// sequence that spans no time.
RecordedOptions FitConfig(const RecordedSequence& seq, double batch_window,
                          scenario::ScenarioConfig* config);

}  // namespace dualgrid::cosim
