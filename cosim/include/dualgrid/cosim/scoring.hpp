// Scoring one filter cycle (paper Sec. V): picks the particles of dynamic cells, clusters them,
// scores the clusters against the ground truth and classifies cells. Everything in the grid frame.
#pragma once

#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "dualgrid/core/grid_frame.hpp"
#include "dualgrid/eval/cell_metrics.hpp"
#include "dualgrid/eval/clustering.hpp"
#include "dualgrid/eval/metrics.hpp"
#include "dualgrid/filter/dynamic_grid.hpp"
#include "dualgrid/scenario/loader.hpp"
#include "dualgrid/sim/ground_truth.hpp"

namespace dualgrid::cosim {

/// Per-cell snapshot of a grid in logical row-major order (index = y * cells_x + x).
struct GridSnapshot {
  int cells_x = 0, cells_y = 0;
  double resolution = 0.0;                    ///< [m]
  std::int64_t origin_ix = 0, origin_iy = 0;  ///< global index of cell (0, 0)
  Position origin = Position::Zero();         ///< lower-left corner of cell (0, 0), grid frame [m]
  std::vector<float> free, static_occ, dynamic;
  std::vector<std::uint8_t> observed;
  /// Mean velocity over ground [m/s] per cell; empty unless taken `with_velocity`.
  std::vector<float> mean_vx, mean_vy;
  /// eval::CellClass per cell at `classes_threshold` (ClassifySnapshot); empty, with a NaN
  /// threshold, after TakeSnapshot. Code that writes the masses otherwise must clear them too.
  std::vector<std::uint8_t> classes;
  double classes_threshold = std::numeric_limits<double>::quiet_NaN();
};
/// Fills `s` (reusing its storage). The velocity moments cost a pass over every particle and are
/// needed only for figures and particle files, so scoring takes it without them.
void TakeSnapshot(const filter::DynamicGrid& grid, bool with_velocity, GridSnapshot& s);
/// Fills s.classes with eval::ClassifyCells of its masses at `threshold`. The scorer then reads
/// these bytes and `observed` (2 bytes per cell) instead of the masses and `observed` (13): called
/// on the thread that took the snapshot, it keeps the scorer on another core from pulling the
/// masses over, which the filter's next ExportMasses would pull back (docs/performance.md, round
/// 5).
void ClassifySnapshot(double threshold, GridSnapshot& s);
/// Adds the velocity moments to a snapshot taken without them from the same grid state:
/// TakeSnapshot(grid, false, s) then TakeVelocities(grid, s) equals TakeSnapshot(grid, true, s).
void TakeVelocities(const filter::DynamicGrid& grid, GridSnapshot& s);

/// Ground-truth class per cell: moving vehicles dynamic; parked boxes and guard rails (as boxes
/// one cell wide) static; the rest free. The world's boxes are mapped into the grid frame and
/// culled to the grid first.
std::vector<std::uint8_t> TruthClasses(const GridSnapshot& grid, const GridFrame& grid_frame,
                                       const sim::Frame& frame, const sim::ScenarioSpec& spec);

/// The logical cells of a grid near a box: every cell holding a point of `box` (its bounding
/// rectangle widened by one cell) lies in [x0, x1] x [y0, y1]. Empty for a non-finite box.
struct CellWindow {
  double x0 = 0.0, x1 = -1.0, y0 = 0.0, y1 = -1.0;  ///< cell indices (as doubles: no overflow)
  static CellWindow Around(const OrientedBox& box, const filter::DynamicGrid& grid);
  bool Holds(int x, int y) const { return x >= x0 && x <= x1 && y >= y0 && y <= y1; }
};

/// The particles the paper clusters (Sec. V): `grid`'s weighted particles (after the weight
/// update, before resampling; weights normalised per cell to its dynamic mass) in the cells whose
/// `classes` entry (eval::CellClass per cell, index y * cells_x + x) is dynamic, with a positive
/// weight and outside `exclude` (the ego's box: nothing else can be there). Grid frame. Replaces
/// `out`'s contents, in the particles' order. With `cells`, also replaces its contents with the
/// grid cells of `out` (logical (x, y), the grid frame's origin and resolution: a grouping for
/// eval::Dbscan::RunInCells). Throws std::invalid_argument when classes.size() is not the grid's
/// cell count.
void DynamicParticles(const filter::DynamicGrid& grid, std::span<const std::uint8_t> classes,
                      const std::optional<OrientedBox>& exclude,
                      std::vector<eval::WeightedParticle>* out, eval::PointCells* cells = nullptr);

class ModeScorer {
 public:
  explicit ModeScorer(const scenario::EvaluationConfig& config);
  /// Scores one cycle. `snapshot` is TakeSnapshot(grid, ...), with its classes if
  /// ClassifySnapshot ran at this scorer's threshold (else they are computed here, the same
  /// values); `truth_classes` from TruthClasses.
  /// All positions in the grid frame. Particles inside `ego_box` are not clustered: no other object
  /// can be there, and particles there would chain the vehicles on both sides of the ego into one
  /// cluster.
  void AddFrame(double time, const filter::DynamicGrid& grid, const GridSnapshot& snapshot,
                const std::vector<eval::TruthObject>& objects,
                const std::vector<std::uint8_t>& truth_classes, const OrientedBox& ego_box);
  /// Scores this cycle's labelled points (recorded data; eval/point_metrics.hpp): `positions` in
  /// the grid frame, `labels` RadarScenes label ids (-1: unlabelled, not counted); points inside
  /// `ego_box` are not counted (the filter never sees them). After AddFrame of the same cycle.
  void AddPoints(const filter::DynamicGrid& grid, const GridSnapshot& snapshot,
                 const std::vector<Position>& positions, const std::vector<int>& labels,
                 const OrientedBox& ego_box);
  eval::ScenarioMetrics Result() const;
  /// Clusters of the last frame and their association.
  const std::vector<eval::Cluster>& clusters() const { return clusters_; }
  const eval::AssociationResult& association() const { return association_; }

 private:
  scenario::EvaluationConfig config_;
  eval::ParticleClusterer clusterer_;
  eval::TrackingMetricsAccumulator tracking_;
  eval::CellClassificationAccumulator cells_;
  std::optional<eval::PointClassificationAccumulator> points_;
  std::vector<eval::WeightedParticle> dynamic_particles_;
  eval::PointCells dynamic_cells_;  // their grid cells
  std::vector<eval::Cluster> clusters_;
  eval::AssociationResult association_;
  std::vector<std::uint8_t> predicted_;
};

}  // namespace dualgrid::cosim
