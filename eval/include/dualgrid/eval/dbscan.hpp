// DBSCAN (Ester et al., KDD 1996) over 2-D points with a uniform-grid spatial index.
//
// Used to cluster the particles of dynamic cells (paper Sec. V). The points are sorted into a
// fine grid of side h < eps / sqrt(2) (Gunawan's grid DBSCAN): two points of one fine cell are
// neighbours, so a cell holding min_points points makes them all core without a distance, and
// the neighbours of a point lie in the 5 x 5 block of cells around its own. The clusters
// (components of the core graph) are found on the same grid: two fine cells are joined after
// the first pair of their core points within eps, so dense clusters cost O(cells), not
// O(points x density). With the weighted criterion (min_weight > 0), the core test sums the
// weights over index cells of side eps in a fixed order instead (the 3 x 3 block, own cell
// first). RunInCells takes the fine grid from the caller (points already grouped by the cells of
// a lattice, e.g. the filter's grid cells), with a neighbour block as wide as its side needs.
// Speed: docs/performance.md (bench_models' clusterer, bench_scoring).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include <nlohmann/json.hpp>

#include "dualgrid/core/types.hpp"

namespace dualgrid::eval {

struct DbscanParams {
  /// Neighbourhood radius [m]; a point at distance exactly eps is a neighbour. 1.0 m = two cells
  /// of the 0.5 m grid: particles of diagonally adjacent cells (0.71 m apart) link and a single
  /// empty cell inside a vehicle is bridged, while vehicles in adjacent lanes (3.5 m lanes,
  /// <= 2.5 m wide vehicles, so >= 1 m apart) stay separate unless they touch.
  double eps = 1.0;
  /// A point is core when its neighbour count within eps, itself included, is >= min_points.
  /// 3 rejects one or two isolated particles (spurious birth) while any vehicle holding a few
  /// dozen particles forms a cluster.
  int min_points = 3;
  /// Optional weighted criterion: a core point must also have a neighbour weight sum (itself
  /// included) >= min_weight. 0 disables it; ignored when no weights are given.
  double min_weight = 0.0;

  bool IsValid(std::string* error) const;
};

/// Records the parameters used (run folders keep their configuration).
void to_json(nlohmann::json& j, const DbscanParams& p);

/// Label of points that belong to no cluster.
inline constexpr int kNoise = -1;

/// One cell of a lattice of square cells and the points it holds (Dbscan::RunInCells).
struct CellRun {
  std::int64_t x = 0,
               y = 0;  ///< the cell's lattice index: it spans origin + (x, y) side + [0, side]^2
  int first = 0;       ///< its first point; it holds points [first, the next run's first or n)
};

/// Points grouped by the square cells of a lattice (for the scorer: the filter's grid cells).
struct PointCells {
  Position origin = Position::Zero();  ///< lower-left corner of cell (0, 0) [m]
  double side = 0.0;                   ///< cell edge [m]
  std::vector<CellRun> runs;           ///< in point order, one per non-empty cell
};

/// Reusable DBSCAN runner; keeps its buffers between calls so per-frame use does not allocate
/// once warmed up.
///
/// Determinism: core points form clusters as connected components of the core graph, which does
/// not depend on input order. A border point (not core, within eps of a core point) joins the
/// cluster of its nearest core neighbour, ties broken by the lexicographically smaller (x, y) of
/// that core point, so permuting the input keeps the partition (unlike textbook DBSCAN, where a
/// border point joins whichever cluster reaches it first). Cluster labels 0, 1, ... are numbered
/// in order of each cluster's lowest input index.
class Dbscan {
 public:
  explicit Dbscan(const DbscanParams& params = {});

  /// Clusters `points`; `weights` is empty or one non-negative weight per point. Returns one label
  /// per point (cluster index or kNoise), valid until the next call.
  /// Throws std::invalid_argument on a size mismatch or a non-finite point.
  std::span<const int> Run(std::span<const Position> points, std::span<const double> weights = {});
  /// The same labels as Run(points, weights), for points grouped by `cells` (each point within
  /// its run's cell up to 1e-3 of the side): the cells serve as the fine grid, so no point is
  /// located, and a cell of side < eps / sqrt(2) holding min_points points makes them all core.
  /// Falls back to Run when the weighted criterion applies, the side is not in (eps / 4, inf), a
  /// point lies outside its cell or a cell has two runs. Throws std::invalid_argument as Run
  /// does, and for runs whose firsts do not rise strictly from 0 below points.size().
  std::span<const int> RunInCells(std::span<const Position> points, std::span<const double> weights,
                                  const PointCells& cells);

  int num_clusters() const { return num_clusters_; }
  const DbscanParams& params() const { return params_; }

 private:
  static constexpr int kNear = 9;  // the 3 x 3 hash cells around a point's own
  // near_[kNear b ...]: the existing buckets among the 3 x 3 hash cells around bucket b, in the
  // search order (own cell first), padded with -1.
  void NearBuckets(int num_buckets);
  // Calls f(t) for every sorted position t within eps of sorted position s of bucket b (s itself
  // included) until f returns false.
  template <typename F>
  void ForEachNeighbour(int b, int s, F&& f) const;

  DbscanParams params_;
  double inv_eps_ = 1.0;
  // Maps integer cell coordinates to cell ids numbered by first appearance. A dense array (with a
  // border of `pad` cells holding -1) when the keys' bounding rectangle is small (up to
  // 8 n + 65,536 cells: a grid-sized scene), else a hash map. The dense array is kept between
  // builds: a build resets only the entries the last one set (`used`), the rest hold -1 already.
  struct CellTable {
    bool dense = false;
    std::int64_t x0 = 0, y0 = 0, w = 0;
    std::vector<int> cells;  // every entry not listed in `used` is -1
    std::vector<std::size_t> used;
    std::unordered_map<std::uint64_t, int> map;
    // Assigns ids to the cells of (ix[k], iy[k]) into id[k]; returns the number of cells.
    int Build(std::span<const std::int64_t> ix, std::span<const std::int64_t> iy, int pad,
              std::span<int> id);
    // Id of a cell within `pad` of a built key, -1 if it holds none.
    int Find(std::int64_t x, std::int64_t y) const;
  };

  // 1 / h, the fine grid's inverse cell side [1/m] (h < eps / sqrt(2)).
  double InvFineSide() const;
  // The fine grid of all points: fx_, fy_, fine_cell_ per point; cell c, at (cx_[c], cy_[c]),
  // holds the points fine_sorted_[fine_start_[c] .. fine_start_[c + 1]) in input order.
  void FineCells(std::span<const Position> points);
  // The fine grid given by `cells` (fine_sorted_ the identity); false (nothing usable built) when
  // a point lies outside its cell or a cell has two runs.
  bool GivenCells(std::span<const Position> points, const PointCells& cells);
  // Core flags, components, borders and labels on the fine grid built (after FineCells or
  // GivenCells).
  std::span<const int> LabelOnFineGrid(std::span<const Position> points,
                                       std::span<const double> weights);
  // Calls f(j) for every point j within eps of point i (itself included) of fine cell c, in the
  // cells of the block of `reach_` cells around c, until f returns false.
  template <typename F>
  void ForEachFineNeighbour(std::span<const Position> points, int c, int i, F&& f) const;
  // Core flags without the weighted criterion: count neighbours on the fine grid.
  void CountCore(std::span<const Position> points);
  // Core flags with it: the weights summed over the eps cells in their fixed order.
  void WeightedCore(std::span<const Position> points, std::span<const double> weights);
  // Core-point components on the fine grid (after FineCells and the core flags); fills
  // component_ for core points, returns the count.
  int CoreComponents(std::span<const Position> points);
  // Joins the components of the core cells `from` with those of the cells in rings first_ring ..
  // last_ring of half_ around them whose core points lie within eps of theirs.
  void JoinRings(std::span<const Position> points, int first_ring, int last_ring,
                 std::span<const int> from);
  // After ring 1 is joined: the core cells within reach_ cells (along both axes) of the bounding
  // rectangle of another ring-1 component, in cell order (all core cells when there are more than
  // a few dozen components). Only their outer rings can join two components.
  std::span<const int> OuterRingCells();
  int FindRoot(int c);

  CellTable buckets_;  // eps cells: bucket b holds sorted_[start_[b] .. start_[b + 1])
  std::vector<std::int64_t> ix_, iy_;
  std::vector<int> bucket_;
  std::vector<int> start_;
  std::vector<int> sorted_;
  std::vector<Position> sorted_pos_;   // points[sorted_[s]]
  std::vector<double> sorted_weight_;  // weights[sorted_[s]] when weighted
  std::vector<int> near_;
  std::vector<std::uint8_t> core_;
  // Fine grid of all points (FineCells); its core points per cell: core_sorted_[core_start_[c] ..
  // core_start_[c + 1]).
  CellTable fine_;
  // The fine grid's neighbour block: points within eps lie at most reach_ cells apart; whole_core_:
  // a cell holding min_points points makes them all core (its diameter is below eps).
  struct Offset {
    int dx, dy;
  };
  // The offsets of cells up to `reach` apart that can hold points within eps: all of them when
  // side is 0 (FineCells); for given cells of `side` [m], those whose gap (less the slack) is
  // within eps. half_: those of the upper half plane (dy > 0, or dy == 0 and dx > 0), ring by ring
  // (ring r: half_[ring_start_[r - 1] .. ring_start_[r])); block_: all, (0, 0) included.
  void SetBlock(int reach, double side);
  int reach_ = 0;
  double block_side_ = -1.0;
  std::vector<Offset> half_, block_;
  std::vector<int> ring_start_;
  bool whole_core_ = true;
  // CountCore made every point of a cell holding min_points points core (whole_core_ without the
  // weighted criterion); fine_sorted_ is the identity (GivenCells: points in cell order).
  bool whole_cells_core_ = false, sorted_is_identity_ = false;
  std::vector<std::int64_t> fx_, fy_, cx_, cy_;
  std::vector<int> fine_cell_, fine_start_, fine_sorted_, parent_, root_component_;
  std::vector<int> core_start_, core_sorted_;
  std::vector<int> core_cells_;             // the cells holding core points
  std::vector<std::ptrdiff_t> half_delta_;  // half_ as steps in the dense table
  // OuterRingCells: the ring-1 components' rectangles [x0, x1] x [y0, y1] in cell indices, each
  // core cell's component (ring1_of_[k] for core_cells_[k]), the components near each one
  // (near_boxes_[near_start_[i] .. near_start_[i + 1])) and the cells it returns.
  struct CellBox {
    std::int64_t x0, x1, y0, y1;
  };
  std::vector<CellBox> ring1_boxes_;
  std::vector<int> ring1_of_, near_start_, near_boxes_, outer_cells_;
  std::vector<int> component_;
  std::vector<int> labels_;
  std::vector<int> relabel_;
  int num_clusters_ = 0;
};

}  // namespace dualgrid::eval
