// Tracking metrics of the paper's Sec. V (Delta x, Delta v, t_d, D) plus false and duplicate
// clusters per scan, accumulated frame by frame.
//
// Definitions (frame = one AddFrame call = one filter cycle; an object "is tracked" in a frame
// when it is in_grid and a cluster is matched to it by Associate; objects are listed from the
// first frame in which they are in_grid or detected_in_grid):
// - Delta x / Delta v: mean over all (frame, tracked object) pairs of
//   ||cluster.position - box.center|| / ||cluster.velocity - object.velocity||.
// - D_v of an object (not in the paper): frames tracked by a cluster whose velocity error is below
//   max(velocity_tolerance, velocity_tolerance_fraction x the object's speed) / frames in_grid.
//   D counts a cluster in the gate whatever its velocity; in the paper a wrong velocity turns the
//   cells static, so its D implicitly needs roughly right dynamics: D_v is that, made explicit.
//   Scenario D_v: mean over scored objects, like D.
// - D of an object: frames tracked / frames in_grid. Objects with fewer than min_frames_in_grid
//   in_grid frames are not scored (too short to say anything). Scenario D: mean over scored
//   objects (each object counts once, as in the paper's "average duration").
// - t_d of an object: the clock starts at the first frame where it is in_coverage and
//   detected_in_grid (time t0): the grid has been shown the object. (Before, the clock started
//   when the box centre entered the grid: an oncoming car, whose front the grid tracks before its
//   centre enters, scored t_d = 0.) From then on each frame in which the object is listed enters
//   a window of the last `window` frames; the object is first "consistently tracked" in the first
//   frame whose window holds >= `required` frames in which a cluster is matched to it with the
//   right velocity (as for D_v; the centre need not be in the grid yet). Its track onset is the
//   time t1 of the earliest tracked frame in that window (when the consistent track began, not when
//   the rule confirmed it; the difference is at most window - 1 frames), and t_d = t1 - t0.
//   Scenario t_d: mean over scored objects that were ever consistently tracked; the others are
//   counted as never tracked (and, if they were never in any radar's coverage while in the grid,
//   also as never observable).
// - False / duplicate clusters per scan: mean over frames of the counts from Associate.
#pragma once

#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dualgrid/eval/association.hpp"
#include "dualgrid/eval/cell_metrics.hpp"
#include "dualgrid/eval/point_metrics.hpp"

namespace dualgrid::eval {

struct TrackingMetricsParams {
  AssociationParams association;
  /// "Consistently tracked": at least `required` tracked frames among the last `window` frames
  /// (4 of 5 at 20 Hz: a track that survives 0.25 s with at most one dropout).
  int required = 4;
  int window = 5;
  /// Objects with fewer in_grid frames are not scored (20 frames = 1 s at 20 Hz).
  int min_frames_in_grid = 20;
  /// D_v: a tracked frame counts when |cluster velocity - object velocity| is below
  /// max(velocity_tolerance [m/s], velocity_tolerance_fraction x |object velocity|): 2 m/s is
  /// about the paper's Delta v (Tables I, II: 0.2-3.3 m/s); 20 % keeps the bound meaningful for
  /// fast traffic.
  double velocity_tolerance = 2.0;
  double velocity_tolerance_fraction = 0.2;

  bool IsValid(std::string* error) const;
};

struct ObjectMetrics {
  int id = 0;
  int frames_in_grid = 0;
  int frames_tracked = 0;                    ///< in_grid frames with a matched cluster
  int frames_tracked_v = 0;                  ///< ... whose velocity is within the tolerance
  bool scored = false;                       ///< frames_in_grid >= min_frames_in_grid
  std::optional<double> first_in_grid_time;  ///< [s]
  std::optional<double> clock_start_time;    ///< first in_grid && in_coverage frame [s]
  std::optional<double> track_onset_time;    ///< t1 of the t_d definition [s]
  std::optional<double> tracked_fraction;    ///< D in [0, 1]; empty if never in_grid
  std::optional<double> tracked_fraction_v;  ///< D_v in [0, 1]; empty if never in_grid
  std::optional<double> detection_time;      ///< t_d [s]; empty if never consistently tracked
  std::optional<double> position_error;      ///< mean over its tracked frames [m]
  std::optional<double> velocity_error;      ///< [m/s]
};

struct ScenarioMetrics {
  int frames = 0;
  std::int64_t matches = 0;              ///< (frame, tracked object) pairs behind the errors
  std::optional<double> position_error;  ///< Delta x [m]
  /// Diagnostic beside Delta x: mean distance from the cluster to the vehicle's box (0 inside).
  /// Radar sees only the faces turned to it, so clusters sit on a face; this separates that
  /// offset (up to half a length) from errors of the filter itself.
  std::optional<double> box_distance;
  std::optional<double> velocity_error;      ///< Delta v [m/s]
  std::optional<double> detection_time;      ///< t_d [s]
  std::optional<double> tracked_fraction;    ///< D in [0, 1]
  std::optional<double> tracked_fraction_v;  ///< D_v in [0, 1]
  int objects_scored = 0;
  int objects_detected = 0;          ///< scored and ever consistently tracked
  int objects_never_tracked = 0;     ///< scored, never consistently tracked (for any reason)
  int objects_never_observable = 0;  ///< of those: clock never started (never detected in the
                                     ///< grid while in coverage)
  double clusters_per_scan = 0.0;
  double false_clusters_per_scan = 0.0;
  double duplicate_clusters_per_scan = 0.0;
  std::optional<CellMetrics> cells;  ///< filled by the caller from CellClassificationAccumulator
  /// Point-level dynamic classification, for labelled recorded data only (point_metrics.hpp);
  /// absent from the JSON when empty.
  std::optional<PointMetrics> points;
  std::vector<ObjectMetrics> objects;  ///< every object ever in_grid, ascending id
};

/// Feeds frames in time order and produces ScenarioMetrics. Allocation per frame is small (the
/// association cost matrix); objects are keyed by id.
class TrackingMetricsAccumulator {
 public:
  explicit TrackingMetricsAccumulator(const TrackingMetricsParams& params = {});

  /// One filter cycle at `time` [s] (strictly increasing). `objects` lists the vehicles present
  /// (ids unique within the frame). Returns the association, e.g. for figures.
  /// Throws std::invalid_argument on a non-increasing time or a repeated id.
  AssociationResult AddFrame(double time, std::span<const Cluster> clusters,
                             std::span<const TruthObject> objects);

  ScenarioMetrics Result() const;

 private:
  struct ObjectState {
    int frames_in_grid = 0;
    int frames_tracked = 0;
    int frames_tracked_v = 0;
    std::optional<double> first_in_grid_time, clock_start_time, track_onset_time;
    std::vector<std::pair<double, bool>> window;  // (time, tracked), oldest first, <= window
    double position_error_sum = 0.0, velocity_error_sum = 0.0;
  };
  double box_distance_sum_ = 0.0;

  TrackingMetricsParams params_;
  std::map<int, ObjectState> objects_;
  std::optional<double> last_time_;
  int frames_ = 0;
  std::int64_t clusters_ = 0, false_clusters_ = 0, duplicate_clusters_ = 0, matches_ = 0;
  double position_error_sum_ = 0.0, velocity_error_sum_ = 0.0;
};

void to_json(nlohmann::json& j, const TrackingMetricsParams& p);
void to_json(nlohmann::json& j, const ObjectMetrics& m);
void from_json(const nlohmann::json& j, ObjectMetrics& m);
void to_json(nlohmann::json& j, const ScenarioMetrics& m);
void from_json(const nlohmann::json& j, ScenarioMetrics& m);

}  // namespace dualgrid::eval
