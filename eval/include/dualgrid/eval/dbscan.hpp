// DBSCAN (Ester et al., KDD 1996) over 2-D points with a uniform-grid spatial index.
//
// Used to cluster the particles of dynamic cells (paper Sec. V). Neighbour queries look at the
// 3x3 block of hash cells of size eps around a point. Core tests stop at min_points neighbours
// and the cluster search drops points from its index once reached, so a run costs about O(n)
// for bounded density (about 1.5 ms for 10^4 particles on two cars, one core).
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

  int num_clusters() const { return num_clusters_; }
  const DbscanParams& params() const { return params_; }

 private:
  // Calls f(j) for every point j within eps of points[i] (i itself included).
  template <typename F>
  void ForEachNeighbour(std::span<const Position> points, int i, F&& f) const;
  // Calls f(bucket) for the existing buckets of the 3 x 3 hash cells around p until f is false.
  template <typename F>
  void ForEachNearBucket(const Position& p, F&& f) const;

  DbscanParams params_;
  double inv_eps_ = 1.0;
  // Spatial hash: key of a cell -> bucket; bucket b holds sorted_[start_[b] .. start_[b + 1]).
  std::unordered_map<std::uint64_t, int> bucket_of_key_;
  std::vector<std::uint64_t> key_;
  std::vector<int> bucket_;
  std::vector<int> start_;
  std::vector<int> sorted_;
  std::vector<std::uint8_t> core_;
  // Core-only index of unvisited core points (same buckets), for the cluster search.
  std::vector<int> core_start_;
  std::vector<int> core_live_;
  std::vector<int> core_sorted_;
  std::vector<int> slot_;
  std::vector<int> component_;
  std::vector<int> stack_;
  std::vector<int> labels_;
  std::vector<int> relabel_;
  int num_clusters_ = 0;
};

}  // namespace dualgrid::eval
