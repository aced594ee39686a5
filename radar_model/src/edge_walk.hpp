// Several edges walked at once (internal to radar_model/src): the samples WalkEdge
// (scan_geometry.hpp) emits, bit for bit, with the edges on SIMD lanes.
#pragma once

#include <vector>

#include "dualgrid/core/types.hpp"

namespace dualgrid::radar::detail {

/// An edge a -> b [m] (world frame).
struct Edge {
  Position a, b;
};

/// What the scan's first tests need of a sensor (RadarModel::VisibleScatterers' `consider`): a
/// point q is kept when its local coordinates local = to_local * (q - position) and range =
/// local.norm() pass !(range < min_range), !(range > max_range) and !OutsideFov(local, range,
/// fov_cos_bound).
struct SensorCone {
  Position position = Position::Zero();     // [m] world frame
  Matrix2 to_local = Matrix2::Identity();   // world -> sensor frame rotation
  double min_range = 0.0, max_range = 0.0;  // [m]
  double fov_cos_bound = -1.0;              // FovCosBound(half field of view) [-]
};

/// One kept sample of a walked edge: its midpoint q [m] and length ds [m] (WalkEdge's), and q
/// in the sensor's frame with its range [m] (as the scan computes them).
struct EdgeSample {
  Position q;
  double ds;
  Position local;
  double range;
};

/// Walks every edge of edges[0, n) as WalkEdge(a, b, cone.position, range_res, azimuth_res,
/// emit) does and stores, in WalkEdge's order, those of edge i's samples that the cone keeps in
/// (*samples)[i] (grown to n entries if shorter; entries i < n cleared first, their capacity
/// kept, later ones left alone). The values are bit for bit those of the scalar code: each lane
/// performs the same IEEE operations in the same order (SSE4, no FMA). WalkEdge's third value
/// (the sine at the sample) is not computed. Walking several edges at once hides the latency of
/// each edge's chain of square roots and divisions (every sample's spacing depends on the last).
void WalkEdges(const Edge* edges, int n, const SensorCone& cone, double range_res,
               double azimuth_res, std::vector<std::vector<EdgeSample>>* samples);

}  // namespace dualgrid::radar::detail
