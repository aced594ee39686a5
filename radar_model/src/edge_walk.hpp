// Several edges walked at once (internal to radar_model/src): the samples WalkEdge
// (scan_geometry.hpp) emits, bit for bit, with the edges on SIMD lanes.
#pragma once

#include <limits>

#include "dualgrid/core/types.hpp"

namespace dualgrid::radar::detail {

/// An edge a -> b [m] (world frame), walked for the sensor cones[cone] (the multi-cone
/// WalkEdges; the one-cone overload ignores `cone`). Parameters along the edge [m], from the
/// caller's proof that the scan rejects the samples they leave out: samples whose midpoint lies
/// before `begin` or in [skip_lo, skip_hi] are walked but not handed on; the walk stops at the
/// first sample that starts at or beyond `stop`. The samples handed on are those of the whole
/// walk, bit for bit.
struct Edge {
  Position a, b;
  int cone = 0;
  double stop = std::numeric_limits<double>::infinity();
  double begin = 0.0;
  double skip_lo = std::numeric_limits<double>::infinity();
  double skip_hi = -std::numeric_limits<double>::infinity();
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
  // WalkEdge's resolutions, used by the multi-cone WalkEdges (the one-cone overload takes its
  // own): range [m], azimuth [rad].
  double range_res = 1.0, azimuth_res = 1.0;
};

/// One kept sample of a walked edge: its midpoint q [m] and length ds [m] (WalkEdge's), and q
/// in the sensor's frame with its range [m] (as the scan computes them).
struct EdgeSample {
  Position q;
  double ds;
  Position local;
  double range;
};

/// Receives the kept samples: sink(context, edge, sample) for edge `edge` (an index into the
/// walked edges), in WalkEdge's order within each edge; the edges' samples come interleaved.
using SampleSink = void (*)(void* context, int edge, const EdgeSample& sample);

/// Walks every edge of edges[0, n) as WalkEdge(a, b, cone.position, range_res, azimuth_res,
/// emit) does and hands the samples that the cone keeps to `sink`. The values are bit for bit
/// those of the scalar code: each lane performs the same IEEE operations in the same order
/// (SSE4, no FMA). WalkEdge's third value (the sine at the sample) is not computed. Walking
/// several edges at once hides the latency of each edge's chain of square roots and divisions
/// (every sample's spacing depends on the last), and so does the sink's work done in between.
void WalkEdges(const Edge* edges, int n, const SensorCone& cone, double range_res,
               double azimuth_res, SampleSink sink, void* context);

/// The same for edges of several sensors at once: edge i is walked as WalkEdge(a, b,
/// cones[edges[i].cone].position, that cone's range_res, azimuth_res, emit) and its samples kept
/// by that cone. Each edge's samples come in WalkEdge's order; the edges' come interleaved (in
/// an order that depends on their lengths), so a sink must not depend on the order across edges.
/// Lanes of different sensors in one vector overlap their chains: with all sensors' edges in one
/// call, more chains are in flight than one sensor's 2-3 rail pieces give.
void WalkEdges(const Edge* edges, int n, const SensorCone* cones, SampleSink sink, void* context);

/// WalkEdges with a callable sink(int edge, const EdgeSample& sample).
template <class Sink>
void WalkEdges(const Edge* edges, int n, const SensorCone& cone, double range_res,
               double azimuth_res, Sink& sink) {
  WalkEdges(
      edges, n, cone, range_res, azimuth_res,
      [](void* context, int edge, const EdgeSample& sample) {
        (*static_cast<Sink*>(context))(edge, sample);
      },
      &sink);
}

/// The multi-cone WalkEdges with a callable sink(int edge, const EdgeSample& sample).
template <class Sink>
void WalkEdges(const Edge* edges, int n, const SensorCone* cones, Sink& sink) {
  WalkEdges(
      edges, n, cones,
      [](void* context, int edge, const EdgeSample& sample) {
        (*static_cast<Sink*>(context))(edge, sample);
      },
      &sink);
}

}  // namespace dualgrid::radar::detail
