// Association of particle clusters with ground-truth vehicles.
//
// Gate. In the object's own frame (x along its heading, y to its left), with d the offset of the
// cluster position from the box centre, L and W the box length and width, a cluster is inside
// the gate of an object when EITHER
//   (box gate)     |d.x| <= L/2 + box_margin  and  |d.y| <= W/2 + box_margin, OR
//   (centre gate)  (d.x / (center_gate + L/2))^2 + (d.y / center_gate)^2 <= 1,
// i.e. an ellipse around the centre whose semi-axis along the heading is stretched by half the
// length. The box gate accepts clusters covering any part of a long vehicle (a truck's front
// half); the ellipse tolerates a lagging or leading estimate along the direction of motion,
// where the filter errs most.
//
// Assignment. One cluster per object at most, chosen by an optimal assignment (Hungarian
// algorithm): first the number of matched pairs is maximised, then the sum of centre distances
// ||cluster.position - box.center|| over the matched pairs is minimised. Unmatched clusters are
// "duplicate" when they lie in the gate of some object (then every object they gate is already
// matched, by maximality: e.g. the second half of a split truck) and "false" otherwise.
#pragma once

#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dualgrid/core/types.hpp"
#include "dualgrid/eval/clustering.hpp"

namespace dualgrid::eval {

/// A ground-truth vehicle at one time step, in the clusters' frame (in dualgrid the grid frame,
/// docs/algorithm.md: the scorer maps the truth into it).
struct TruthObject {
  int id = 0;                            ///< stable over frames (e.g. SUMO vehicle index)
  OrientedBox box;                       ///< footprint; box.center is the reference point
  Velocity velocity = Velocity::Zero();  ///< velocity of the box centre [m/s]
  bool in_grid = false;                  ///< its centre lies inside the grid
  bool in_coverage = false;              ///< at least one radar field of view sees it
  /// At least one of this cycle's radar detections from it lies inside the grid: the t_d clock
  /// starts no earlier (the grid cannot track what it has not been shown).
  bool detected_in_grid = false;
};

struct AssociationParams {
  /// Growth of the box on every side for the box gate [m].
  double box_margin = 1.0;
  /// Across-heading semi-axis of the centre ellipse, added to L/2 along the heading [m].
  double center_gate = 2.5;

  bool IsValid(std::string* error) const;
};

void to_json(nlohmann::json& j, const AssociationParams& p);

enum class ClusterRole { kMatched, kDuplicate, kFalse };

struct AssociationResult {
  std::vector<int> object_of_cluster;  ///< matched object index per cluster, -1 if none
  std::vector<int> cluster_of_object;  ///< matched cluster index per object, -1 if none
  std::vector<ClusterRole> role;       ///< per cluster
  int num_matched = 0;
  int num_duplicate = 0;
  int num_false = 0;
};

/// True when `p` lies inside the gate of `object` (see the file comment).
bool InGate(const Position& p, const TruthObject& object, const AssociationParams& params);

/// Associates clusters with all given objects (whatever their in_grid / in_coverage flags: a
/// cluster on a vehicle just outside the grid is not a false cluster). Deterministic.
/// Throws std::invalid_argument for invalid params.
AssociationResult Associate(std::span<const Cluster> clusters, std::span<const TruthObject> objects,
                            const AssociationParams& params = {});

/// Minimum-cost assignment on a rows x cols cost matrix (row-major); entries that are +infinity
/// are forbidden. Maximises the number of assigned rows first, then minimises total cost.
/// Returns the column per row (-1 when unassigned). Exposed for testing.
std::vector<int> SolveAssignment(std::span<const double> cost, int rows, int cols);

}  // namespace dualgrid::eval
