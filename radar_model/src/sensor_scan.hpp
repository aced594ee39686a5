// One sensor's visible scatterers in phases (internal to radar_model/src), so that the sensors of
// a step can walk their guard rails together on SIMD lanes: the constructor culls the scene and
// samples the boxes, ScanRails walks the rail pieces of several scans at once, then AddGhosts.
// RadarModel::VisibleScatterers and RadarModel::Scan run the same phases, so a sensor's
// scatterers do not depend on which sensors walk with it.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "dualgrid/radar_model/radar_model.hpp"
#include "edge_walk.hpp"
#include "scan_geometry.hpp"

namespace dualgrid::radar::detail {

/// A rail segment clipped to a sensor's range disc (in its field of view).
struct RailPiece {
  int polyline;
  Position a, b;     ///< [m] world
  int segment;       ///< the segment's index over all polylines
  double rcs_per_m;  ///< [m^2 / m]
  /// [m along a -> b] the scan rejects every sample whose midpoint lies before walk_begin (Edge::
  /// begin) and every sample that starts at or beyond walk_end (Edge::stop); walk_end 0: the
  /// whole piece is rejected (not walked).
  double walk_begin = 0.0;
  double walk_end = std::numeric_limits<double>::infinity();
  /// [m along a -> b] the scan rejects every sample whose midpoint lies in [skip.lo, skip.hi]
  /// (Edge::skip_lo, skip_hi; a box's shadow across the piece).
  Span skip{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
};

/// What the scan needs of a target whatever the sensor, computed once per step (the same values
/// the scan computed per sensor): its corners, inside test, half diagonal, length axis and RCS.
struct TargetGeometry {
  std::array<Position, 4> corners;  ///< OrientedBox::Corners()
  BoxTest inside;
  double half_diagonal = 0.0;       ///< [m]
  Vector2 axis = Vector2::UnitX();  ///< UnitVector(yaw)
  double rcs_m2 = 0.0;              ///< 10^(rcs_dbsm / 10) [m^2]
  explicit TargetGeometry(const Target& t);
};

/// The TargetGeometry of every target of `scene`, in its order (`out` reused).
void ComputeTargetGeometry(const Scene& scene, std::vector<TargetGeometry>* out);

/// Regions of the plane whose every point a sensor's scan rejects, each the intersection of its
/// half-planes (a point kCutDistance inside all of them is rejected): beyond the field of view
/// widened by kFovCutAngle (one half-plane each; none when the view is too wide or narrow for
/// the wedge to be the intersection of two), and behind the ego's body (five half-planes each).
struct RejectedRegions {
  int fov = 0;
  std::array<HalfPlane, 2> fov_outside;
  int body = 0;
  std::array<std::array<HalfPlane, 5>, 4> behind_body;
};

/// The shadow of a box (corners) seen from s [m], an intersection of three half-planes: beyond
/// the segment between its outermost corners moved kShadowInset of the way to the centre (by
/// kOcclusionShrink more), between the lines from s through them. A line of sight to a point
/// kCutDistance inside all three, shrunk by kOcclusionShrink, crosses the box's inside.
/// std::nullopt when s is not clear of that segment.
std::optional<std::array<HalfPlane, 3>> BoxShadow(const Position& s,
                                                  const std::array<Position, 4>& corners);

/// The regions of a sensor at s [m] with half field of view half_fov [rad] and world -> sensor
/// rotation to_local; the body's when `body` (the shrunk ego box BehindBody tests) is given.
RejectedRegions MakeRejectedRegions(const Position& s, const Matrix2& to_local, double half_fov,
                                    const Occluder* body);

/// One sensor's working memory, kept between steps so that a scan allocates nothing once warmed
/// up. Each scan in flight has its own; every user clears what it takes.
struct ScanScratch {
  std::vector<Occluder> occluders;
  std::vector<int> candidate_targets;
  std::vector<RailPiece> rail_pieces;
  std::vector<int> piece_of;           // the rail piece of each kept rail scatterer
  std::vector<int> piece_starts;       // GroupByPiece's counts
  std::vector<Scatterer> rail_buffer;  // GroupByPiece's copy
  std::vector<std::vector<int>> bins;  // kAzimuthBins lists when occlusion is on
  std::vector<FaceSample> samples;
  std::vector<Span> spans;                        // CutRailWalks' spans of rejected samples
  std::vector<std::array<HalfPlane, 3>> shadows;  // CutRailWalks' box shadows
  std::vector<Scatterer> scatterers;              // the scan's result
  std::vector<Detection> detections;              // RadarModel::Scan's, per sensor
  std::vector<std::pair<std::uint64_t, std::uint32_t>> cells;  // (resolution cell, scatterer)
};

/// The scan of one sensor. Holds references to its arguments until it is done.
class SensorScan {
 public:
  /// Steps 1 and 2: occluders, azimuth bins and rail pieces, then the boxes' scatterers appended
  /// to scratch.scatterers (cleared first). `targets` is ComputeTargetGeometry(scene).
  SensorScan(const SensorParams& p, const SensorModel& model, const ModelOptions& options,
             const EgoMotion& ego, const Scene& scene, const std::vector<TargetGeometry>& targets,
             ScanScratch& scratch);

  /// Step 3 input: the rail pieces to walk and the cone that keeps their samples.
  const std::vector<RailPiece>& rail_pieces() const { return scratch_.rail_pieces; }
  const SensorCone& cone() const { return cone_; }
  /// Step 3: a sample of rail piece k that the cone kept, in the walk's order within the piece.
  void ConsiderRailSample(int k, const EdgeSample& e);
  /// After the last rail sample: the rail scatterers put piece after piece.
  void FinishRails();
  /// Step 4 (multipath on): the boxes' ghosts.
  void AddGhosts();

 private:
  void CullTargets();
  void CullRails();
  void FillBins();
  void CutRailWalks();
  void CutRailWalk(RailPiece& piece);
  bool HidesWhole(const Occluder& o, const Position& p0, const Position& p1) const;
  void AddBoxes();
  Position LocalOf(const Position& q) const { return to_local_ * (q - s_); }
  bool InFov(const Interval& iv) const;
  bool BehindBody(const Position& q) const;
  bool BehindOthers(const Position& q, int owner, const Polar& truth) const;
  bool ConsiderKept(const Position& q, const Position& local, double range, const Velocity& v,
                    double rcs_m2, int source_id, int owner);
  void Consider(const Position& q, const Velocity& v, double rcs_m2, int source_id, int owner);

  const SensorParams& p_;
  const SensorModel& model_;
  const ModelOptions& options_;
  const EgoMotion& ego_;
  const Scene& scene_;
  const std::vector<TargetGeometry>& targets_;
  ScanScratch& scratch_;
  Position s_;
  Velocity vs_;
  double half_fov_;
  Matrix2 to_local_;
  double bin_width_;
  double fov_cos_bound_;
  Occluder body_;
  bool has_body_;
  SensorCone cone_;
  std::size_t rail_begin_ = 0;  // the first rail scatterer in scratch.scatterers
  RejectedRegions rejected_;    // CutRailWalks
};

/// ScanRails' working memory.
struct RailWalkScratch {
  std::vector<Edge> edges;
  std::vector<SensorCone> cones;
  std::vector<std::pair<int, int>> owner_of;  // (scan, piece) of each edge
};

/// Step 3 of every scan of `scans`: their rail pieces walked together (WalkEdges with one cone
/// per scan), each kept sample handed to its scan, then FinishRails. Each piece is walked up to
/// its walk_end (a hidden piece not at all), its samples before walk_begin and in its skip not
/// handed on; with `cut` false every piece is walked whole and every kept sample handed on (the
/// same scatterers: the reference of the tests).
void ScanRails(std::span<SensorScan* const> scans, RailWalkScratch& scratch, bool cut = true);

}  // namespace dualgrid::radar::detail
