// The CSV files of a run folder and the results tables, one writer per file (every column:
// docs/output.md). A writer of a per-step file appends a step per Write() and checks every write
// at Close() (std::runtime_error naming the file); the whole-file writers throw the same way.
// The columns of detections.csv and scans.csv are the ones dualgrid::recorded reads back
// (dualgrid/recorded/run_folder_columns.hpp).
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "dualgrid/cosim/pipeline.hpp"
#include "dualgrid/cosim/scoring.hpp"
#include "dualgrid/eval/aggregate.hpp"
#include "dualgrid/outputs/output_file.hpp"
#include "dualgrid/outputs/weight_traces.hpp"
#include "dualgrid/sim/ground_truth.hpp"
#include "dualgrid/sim/scenario.hpp"

namespace dualgrid::outputs {

/// ground_truth.csv: one row per vehicle (ego included) per step.
class GroundTruthWriter {
 public:
  explicit GroundTruthWriter(const std::filesystem::path& path);
  void Write(const sim::Frame& frame);
  void Close() { out_.Close(); }

 private:
  OutputFile out_;
};

/// grid.csv: where the grid lay, one row per step (world frame).
class GridPoseWriter {
 public:
  explicit GridPoseWriter(const std::filesystem::path& path);
  void Write(const cosim::Pipeline& pipeline);
  void Close() { out_.Close(); }

 private:
  OutputFile out_;
};

/// detections.csv (or detections.csv.gz): one row per radar detection per step. With
/// `multipath` (sensors.multipath on) four columns more name each detection's path: path
/// (direct, type1, type2, clutter), bounces, reflector and ghost_of (docs/output.md).
/// With `exact` (`--detections exact`) every number has 17 significant digits (it reads back as
/// the same double) and a last column `vclass` names the source vehicle's SUMO vClass: the input
/// of `dualgrid filter RUN_DIR` and `dualgrid export` (docs/recorded-data.md).
class DetectionWriter {
 public:
  explicit DetectionWriter(const std::filesystem::path& path, bool multipath = false,
                           bool exact = false);
  void Write(const cosim::Pipeline& pipeline);
  void Close() { out_.Close(); }

 private:
  std::string Number(double v, int decimals) const;

  OutputFile out_;
  bool multipath_;
  bool exact_;
};

/// scans.csv (with `--detections exact`): one row per step and scanning sensor, every number
/// with 17 significant digits: the ego's state (box centre, heading, velocity, yaw rate, box,
/// its lane's direction) and the sensor's mount, field of view and ranges.
class ScanWriter {
 public:
  explicit ScanWriter(const std::filesystem::path& path);
  void Write(const cosim::Pipeline& pipeline);
  void Close() { out_.Close(); }

 private:
  OutputFile out_;
};

/// `--detections exact`: detections.csv with 17 digits, and scans.csv.
inline bool ExactDetections(const std::string& format) { return format == "exact"; }

/// The detection file for a `--detections` format ("csv", "csv.gz" or "exact"); empty for
/// "none".
std::optional<std::filesystem::path> DetectionPath(const std::filesystem::path& dir,
                                                   const std::string& format);

/// obstacles.csv: guard-rail vertices and parked boxes.
void WriteObstacles(const sim::ScenarioSpec& spec, const std::filesystem::path& path);

/// clusters.csv: every cluster of every cycle with its role in the association.
class ClusterWriter {
 public:
  explicit ClusterWriter(const std::filesystem::path& path);
  /// The rows of the clusters of `scorer`'s last frame, for mode `mode`, appended to `out` (the
  /// caller's buffer: the modes' rows may be made concurrently, then appended in mode order by
  /// Append); `objects` as given to the scorer. Clusters are scored in the grid frame and written
  /// in the world frame.
  static void Rows(std::string& out, const sim::Frame& frame, const GridFrame& grid_frame,
                   const std::string& mode, const cosim::ModeScorer& scorer,
                   const std::vector<eval::TruthObject>& objects, const cosim::IdRegistry& ids);
  /// Appends rows made by Rows to the file.
  void Append(const std::string& rows);
  void Close() { out_.Close(); }

 private:
  OutputFile out_;
};

/// figures/particles_<mode>_t<time>.csv: every particle of filter `m` with its cell's P(dynamic).
void WriteParticles(const cosim::Pipeline& pipeline, std::size_t m,
                    const cosim::GridSnapshot& snapshot, const std::filesystem::path& path);

/// objects.csv: one row per (mode, object ever in the grid); with `categories` (object name ->
/// category: annotated data) a last column `category`.
void WriteObjects(const std::vector<std::string>& modes,
                  const std::vector<eval::ScenarioMetrics>& metrics, const cosim::IdRegistry& ids,
                  const std::filesystem::path& path,
                  const std::map<std::string, std::string>* categories = nullptr);

/// weights.csv of one vehicle's trace.
void WriteWeights(const WeightTrace& trace, const std::string& object,
                  const std::filesystem::path& path);

/// table.md, table.csv and table.json.
void WriteTables(const eval::ComparisonTable& table, const std::filesystem::path& dir);

}  // namespace dualgrid::outputs
