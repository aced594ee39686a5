#include "edge_walk.hpp"

#include <algorithm>
#include <vector>

#include <hwy/highway.h>

#include "scan_geometry.hpp"

namespace dualgrid::radar::detail {
namespace {

namespace hn = hwy::HWY_NAMESPACE;
constexpr int kLanes = 2;  // doubles per vector (128 bits)
using DD = hn::FixedTag<double, kLanes>;
using VD = hn::Vec<DD>;
#if HWY_ARCH_X86
// Built for x86-64-v2 (radar_model/CMakeLists.txt): SSE4 lanes, no FMA, the scalar code's bits
// on every x86-64 CPU since 2009.
static_assert(HWY_TARGET == HWY_SSE4, "the radar's SIMD target is pinned to SSE4");
#endif

constexpr int kVectors = 4;                // vectors walked side by side
constexpr int kGroup = kLanes * kVectors;  // edges per group

// One group's edges on lanes: start, direction, length, and their cones' sensor position,
// rotation rows, range limits, field-of-view bound and resolutions; unused lanes have length 0.
struct Lanes {
  alignas(16) double ax[kGroup] = {}, ay[kGroup] = {}, dx[kGroup] = {}, dy[kGroup] = {};
  alignas(16) double len[kGroup] = {};
  alignas(16) double sx[kGroup] = {}, sy[kGroup] = {};
  alignas(16) double m00[kGroup] = {}, m01[kGroup] = {}, m10[kGroup] = {}, m11[kGroup] = {};
  alignas(16) double min_range[kGroup] = {}, max_range[kGroup] = {}, cos_bound[kGroup] = {};
  alignas(16) double range_res[kGroup] = {}, azimuth_res[kGroup] = {};
  alignas(16) double stop[kGroup] = {}, begin[kGroup] = {};  // Edge::stop, Edge::begin
  alignas(16) double skip_lo[kGroup] = {}, skip_hi[kGroup] = {};
  int edge[kGroup] = {};  // the walked edge's index
};

// Lane l of `lanes` set to edge e (index `index`) of cone c; as WalkEdge, nothing for an empty
// edge (its lane keeps length 0).
void SetLane(Lanes& lanes, int l, const Edge& e, int index, const SensorCone& c) {
  lanes.edge[l] = index;
  const double len = (e.b - e.a).norm();
  if (!(len > 0.0)) return;
  const Vector2 dir = (e.b - e.a) / len;
  lanes.ax[l] = e.a.x();
  lanes.ay[l] = e.a.y();
  lanes.dx[l] = dir.x();
  lanes.dy[l] = dir.y();
  lanes.len[l] = len;
  lanes.stop[l] = e.stop;
  lanes.begin[l] = e.begin;
  lanes.skip_lo[l] = e.skip_lo;
  lanes.skip_hi[l] = e.skip_hi;
  lanes.sx[l] = c.position.x();
  lanes.sy[l] = c.position.y();
  lanes.m00[l] = c.to_local(0, 0);
  lanes.m01[l] = c.to_local(0, 1);
  lanes.m10[l] = c.to_local(1, 0);
  lanes.m11[l] = c.to_local(1, 1);
  lanes.min_range[l] = c.min_range;
  lanes.max_range[l] = c.max_range;
  lanes.cos_bound[l] = c.fov_cos_bound;
  lanes.range_res[l] = c.range_res;
  lanes.azimuth_res[l] = c.azimuth_res;
}

// WalkEdge's spacing at pos (min(ds, len - pos)), lane by lane with its comparisons.
VD Spacing(DD d, VD ax, VD ay, VD dx, VD dy, VD len, VD pos, VD sx, VD sy, VD range_res,
           VD azimuth_res) {
  const VD min_spacing = hn::Set(d, kMinSpacing), max_spacing = hn::Set(d, kMaxSpacing);
  const VD rx = hn::Sub(hn::Add(ax, hn::Mul(pos, dx)), sx);
  const VD ry = hn::Sub(hn::Add(ay, hn::Mul(pos, dy)), sy);
  const VD range = hn::Sqrt(hn::Add(hn::Mul(rx, rx), hn::Mul(ry, ry)));
  const VD sin_phi = hn::Div(hn::Abs(hn::Sub(hn::Mul(dx, ry), hn::Mul(dy, rx))), range);
  const VD cos_phi = hn::Div(hn::Abs(hn::Add(hn::Mul(dx, rx), hn::Mul(dy, ry))), range);
  const VD rate =
      hn::Add(hn::Div(sin_phi, hn::Mul(range, azimuth_res)), hn::Div(cos_phi, range_res));
  const VD tiny = hn::Set(d, 1e-12);
  const VD wide = hn::Div(hn::Set(d, 0.5), hn::IfThenElse(hn::Lt(rate, tiny), tiny, rate));
  const VD clamped = hn::IfThenElse(hn::Lt(wide, min_spacing), min_spacing,
                                    hn::IfThenElse(hn::Lt(max_spacing, wide), max_spacing, wide));
  const VD ds = hn::IfThenElse(hn::Gt(range, hn::Set(d, 1e-9)), clamped, min_spacing);
  const VD rest = hn::Sub(len, pos);
  return hn::IfThenElse(hn::Lt(rest, ds), rest, ds);
}

// The cone's tests of the samples at (qx, qy) on lanes [o, o + kLanes), lane by lane as the
// scan's scalar code: the local coordinates and range written to lx, ly, range; the kept lanes
// returned.
hn::Mask<DD> Keep(DD d, const Lanes& c, int o, VD qx, VD qy, double* lx, double* ly,
                  double* range) {
  const VD ex = hn::Sub(qx, hn::Load(d, c.sx + o));
  const VD ey = hn::Sub(qy, hn::Load(d, c.sy + o));
  const VD x = hn::Add(hn::Mul(hn::Load(d, c.m00 + o), ex), hn::Mul(hn::Load(d, c.m01 + o), ey));
  const VD y = hn::Add(hn::Mul(hn::Load(d, c.m10 + o), ex), hn::Mul(hn::Load(d, c.m11 + o), ey));
  const VD r = hn::Sqrt(hn::Add(hn::Mul(x, x), hn::Mul(y, y)));
  hn::Store(x, d, lx);
  hn::Store(y, d, ly);
  hn::Store(r, d, range);
  const auto out = hn::Or(
      hn::Or(hn::Lt(r, hn::Load(d, c.min_range + o)), hn::Gt(r, hn::Load(d, c.max_range + o))),
      hn::Lt(x, hn::Mul(hn::Load(d, c.cos_bound + o), r)));
  return hn::Not(out);
}

void WalkGroup(const Lanes& lanes, int used, SampleSink sink, void* context) {
  const DD d;
  const VD half = hn::Set(d, 0.5);
  VD pos[kVectors];
  for (VD& p : pos) p = hn::Zero(d);
  alignas(16) double keep[kGroup], qx[kGroup], qy[kGroup], step[kGroup];
  alignas(16) double lx[kGroup], ly[kGroup], range[kGroup];
  const int vectors = (used + kLanes - 1) / kLanes;
  for (;;) {
    bool any = false;
    for (int k = 0; k < vectors; ++k) {
      const int o = k * kLanes;
      const VD ax = hn::Load(d, lanes.ax + o), ay = hn::Load(d, lanes.ay + o);
      const VD dx = hn::Load(d, lanes.dx + o), dy = hn::Load(d, lanes.dy + o);
      const VD len = hn::Load(d, lanes.len + o);
      const auto active = hn::And(hn::Lt(pos[k], len), hn::Lt(pos[k], hn::Load(d, lanes.stop + o)));
      if (hn::AllFalse(d, active)) {
        hn::Store(hn::Zero(d), d, keep + o);
        continue;
      }
      any = true;
      const VD ds = Spacing(d, ax, ay, dx, dy, len, pos[k], hn::Load(d, lanes.sx + o),
                            hn::Load(d, lanes.sy + o), hn::Load(d, lanes.range_res + o),
                            hn::Load(d, lanes.azimuth_res + o));
      const VD t = hn::Add(pos[k], hn::Mul(half, ds));
      const VD x = hn::Add(ax, hn::Mul(t, dx)), y = hn::Add(ay, hn::Mul(t, dy));
      const auto skipped = hn::And(hn::Ge(t, hn::Load(d, lanes.skip_lo + o)),
                                   hn::Le(t, hn::Load(d, lanes.skip_hi + o)));
      const auto handed = hn::AndNot(skipped, hn::Ge(t, hn::Load(d, lanes.begin + o)));
      const auto kept =
          hn::And(hn::And(active, handed), Keep(d, lanes, o, x, y, lx + o, ly + o, range + o));
      hn::Store(hn::IfThenElseZero(kept, hn::Set(d, 1.0)), d, keep + o);
      hn::Store(x, d, qx + o);
      hn::Store(y, d, qy + o);
      hn::Store(ds, d, step + o);
      pos[k] = hn::IfThenElse(active, hn::Add(pos[k], ds), pos[k]);
    }
    if (!any) return;
    for (int l = 0; l < used; ++l)
      if (keep[l] != 0.0)
        sink(context, lanes.edge[l],
             EdgeSample{Position(qx[l], qy[l]), step[l], Position(lx[l], ly[l]), range[l]});
  }
}

// Length of an edge's walk [m]: to its end or its stop.
double WalkLength(const Edge& e) { return std::min((e.b - e.a).norm(), e.stop); }

}  // namespace

void WalkEdges(const Edge* edges, int n, const SensorCone* cones, SampleSink sink, void* context) {
  // Longest walks first, so that a group's lanes end at about the same sample (ties by index:
  // the order is the same on every run; the samples do not depend on it).
  thread_local std::vector<int> order;
  thread_local std::vector<double> length;
  order.resize(n);
  length.resize(n);
  for (int i = 0; i < n; ++i) {
    order[i] = i;
    length[i] = WalkLength(edges[i]);
  }
  std::sort(order.begin(), order.end(),
            [&](int i, int j) { return length[i] != length[j] ? length[i] > length[j] : i < j; });
  for (int first = 0; first < n; first += kGroup) {
    const int used = std::min(kGroup, n - first);
    Lanes lanes;
    for (int l = 0; l < used; ++l) {
      const int i = order[first + l];
      SetLane(lanes, l, edges[i], i, cones[edges[i].cone]);
    }
    WalkGroup(lanes, used, sink, context);
  }
}

void WalkEdges(const Edge* edges, int n, const SensorCone& cone, double range_res,
               double azimuth_res, SampleSink sink, void* context) {
  SensorCone c = cone;
  c.range_res = range_res;
  c.azimuth_res = azimuth_res;
  thread_local std::vector<Edge> one_cone;
  one_cone.assign(edges, edges + n);
  for (Edge& e : one_cone) e.cone = 0;
  WalkEdges(one_cone.data(), n, &c, sink, context);
}

}  // namespace dualgrid::radar::detail
