// Particle clusters as in the paper's Sec. V: particles of dynamic cells are clustered with
// DBSCAN and each cluster yields a weighted mean position and velocity.
#pragma once

#include <span>
#include <vector>

#include "dualgrid/core/types.hpp"
#include "dualgrid/eval/dbscan.hpp"

namespace dualgrid::eval {

/// One particle handed over by the filter (the caller passes only particles of cells with
/// P(dynamic) > 0.6), in the filter's frame (in dualgrid the grid frame, docs/algorithm.md).
struct WeightedParticle {
  Position position = Position::Zero();
  Velocity velocity = Velocity::Zero();
  double weight = 0.0;  ///< >= 0; any scale (only ratios within a cluster matter)
};

/// A cluster of particles, in its particles' frame.
struct Cluster {
  Position position = Position::Zero();  ///< weighted mean position [m]
  Velocity velocity = Velocity::Zero();  ///< weighted mean velocity [m/s]
  double weight = 0.0;                   ///< sum of member weights
  int size = 0;                          ///< number of member particles
  Position min = Position::Zero();       ///< axis-aligned bounding box of the members [m]
  Position max = Position::Zero();
};

/// Clusters particles with DBSCAN on their positions; noise particles are dropped. Clusters come
/// in DBSCAN label order (lowest member index first). Means are weighted; a cluster whose weights
/// sum to zero falls back to plain means so that it still reports a location.
/// Reuses its buffers across calls.
class ParticleClusterer {
 public:
  /// Clusters whose summed particle weight is below `min_cluster_weight` are dropped (their
  /// particles labelled noise): a tracked object must hold some minimum dynamic mass.
  explicit ParticleClusterer(const DbscanParams& params = {}, double min_cluster_weight = 0.0);

  /// Throws std::invalid_argument for a negative or non-finite weight or a non-finite particle.
  std::vector<Cluster> Run(std::span<const WeightedParticle> particles);
  /// The same clusters for particles grouped by `cells` (Dbscan::RunInCells; its throws too).
  std::vector<Cluster> Run(std::span<const WeightedParticle> particles, const PointCells& cells);

  /// DBSCAN labels of the particles of the last Run (kNoise or index into its clusters).
  std::span<const int> labels() const { return labels_; }

 private:
  // The plain (unweighted) means of cluster `label`'s particles (labels_ of this Run) into `c`,
  // whose size is set: the fallback of a cluster whose weights sum to zero.
  void PlainMeans(std::span<const WeightedParticle> particles, int label, Cluster& c) const;
  // Both Runs: checked positions and weights into positions_, weights_; DBSCAN labels (of
  // dbscan_.Run or RunInCells) into labels_; then the clusters.
  void TakeParticles(std::span<const WeightedParticle> particles);
  std::vector<Cluster> Clusters(std::span<const WeightedParticle> particles,
                                std::span<const int> labels);

  Dbscan dbscan_;
  double min_cluster_weight_ = 0.0;
  std::vector<Position> positions_;
  std::vector<double> weights_;
  std::vector<int> labels_;
};

}  // namespace dualgrid::eval
