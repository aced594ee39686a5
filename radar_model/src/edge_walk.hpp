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

/// One sample of a walked edge: its midpoint q [m] and its length ds [m].
struct EdgeSample {
  Position q;
  double ds;
};

/// Walks every edge of edges[0, n) as WalkEdge(a, b, sensor, range_res, azimuth_res, emit) does
/// and stores edge i's samples, in WalkEdge's order, in (*samples)[i] (grown to n entries if
/// shorter; entries i < n cleared first, their capacity kept, later ones left alone). The values
/// are WalkEdge's bit for bit: each lane performs the same IEEE operations in the same order (SSE4,
/// no FMA). WalkEdge's third value (the sine at the sample) is not computed. Walking several edges
/// at once hides the latency of each edge's chain of square roots and divisions (every sample's
/// spacing depends on the last).
void WalkEdges(const Edge* edges, int n, const Position& sensor, double range_res,
               double azimuth_res, std::vector<std::vector<EdgeSample>>* samples);

}  // namespace dualgrid::radar::detail
