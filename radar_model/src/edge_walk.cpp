#include "edge_walk.hpp"

#include <algorithm>

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

constexpr int kVectors = 2;                // vectors walked side by side
constexpr int kGroup = kLanes * kVectors;  // edges per group

// One group's edges on lanes: start, direction, length; unused lanes have length 0.
struct Lanes {
  alignas(16) double ax[kGroup] = {}, ay[kGroup] = {}, dx[kGroup] = {}, dy[kGroup] = {};
  alignas(16) double len[kGroup] = {};
};

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

// The cone's tests of the samples at (qx, qy), lane by lane as the scan's scalar code: the
// local coordinates and range written to lx, ly, range; the kept lanes returned.
hn::Mask<DD> Keep(DD d, const SensorCone& cone, VD qx, VD qy, double* lx, double* ly,
                  double* range) {
  const VD ex = hn::Sub(qx, hn::Set(d, cone.position.x()));
  const VD ey = hn::Sub(qy, hn::Set(d, cone.position.y()));
  const Matrix2& m = cone.to_local;
  const VD x = hn::Add(hn::Mul(hn::Set(d, m(0, 0)), ex), hn::Mul(hn::Set(d, m(0, 1)), ey));
  const VD y = hn::Add(hn::Mul(hn::Set(d, m(1, 0)), ex), hn::Mul(hn::Set(d, m(1, 1)), ey));
  const VD r = hn::Sqrt(hn::Add(hn::Mul(x, x), hn::Mul(y, y)));
  hn::Store(x, d, lx);
  hn::Store(y, d, ly);
  hn::Store(r, d, range);
  const auto out =
      hn::Or(hn::Or(hn::Lt(r, hn::Set(d, cone.min_range)), hn::Gt(r, hn::Set(d, cone.max_range))),
             hn::Lt(x, hn::Mul(hn::Set(d, cone.fov_cos_bound), r)));
  return hn::Not(out);
}

void WalkGroup(const Lanes& lanes, int first, int used, const SensorCone& cone, double range_res,
               double azimuth_res, SampleSink sink, void* context) {
  const DD d;
  const VD sx = hn::Set(d, cone.position.x()), sy = hn::Set(d, cone.position.y());
  const VD rr = hn::Set(d, range_res), ar = hn::Set(d, azimuth_res), half = hn::Set(d, 0.5);
  VD pos[kVectors];
  for (VD& p : pos) p = hn::Zero(d);
  alignas(16) double keep[kGroup], qx[kGroup], qy[kGroup], step[kGroup];
  alignas(16) double lx[kGroup], ly[kGroup], range[kGroup];
  for (;;) {
    bool any = false;
    for (int k = 0; k < kVectors; ++k) {
      const int o = k * kLanes;
      const VD ax = hn::Load(d, lanes.ax + o), ay = hn::Load(d, lanes.ay + o);
      const VD dx = hn::Load(d, lanes.dx + o), dy = hn::Load(d, lanes.dy + o);
      const VD len = hn::Load(d, lanes.len + o);
      const auto active = hn::Lt(pos[k], len);
      if (hn::AllFalse(d, active)) {
        hn::Store(hn::Zero(d), d, keep + o);
        continue;
      }
      any = true;
      const VD ds = Spacing(d, ax, ay, dx, dy, len, pos[k], sx, sy, rr, ar);
      const VD t = hn::Add(pos[k], hn::Mul(half, ds));
      const VD x = hn::Add(ax, hn::Mul(t, dx)), y = hn::Add(ay, hn::Mul(t, dy));
      const auto kept = hn::And(active, Keep(d, cone, x, y, lx + o, ly + o, range + o));
      hn::Store(hn::IfThenElseZero(kept, hn::Set(d, 1.0)), d, keep + o);
      hn::Store(x, d, qx + o);
      hn::Store(y, d, qy + o);
      hn::Store(ds, d, step + o);
      pos[k] = hn::IfThenElse(active, hn::Add(pos[k], ds), pos[k]);
    }
    if (!any) return;
    for (int l = 0; l < used; ++l)
      if (keep[l] != 0.0)
        sink(context, first + l,
             EdgeSample{Position(qx[l], qy[l]), step[l], Position(lx[l], ly[l]), range[l]});
  }
}

}  // namespace

void WalkEdges(const Edge* edges, int n, const SensorCone& cone, double range_res,
               double azimuth_res, SampleSink sink, void* context) {
  for (int first = 0; first < n; first += kGroup) {
    const int used = std::min(kGroup, n - first);
    Lanes lanes;
    for (int l = 0; l < used; ++l) {
      const Edge& e = edges[first + l];
      // As WalkEdge: nothing for an empty edge (its lane keeps length 0).
      const double len = (e.b - e.a).norm();
      if (!(len > 0.0)) continue;
      const Vector2 dir = (e.b - e.a) / len;
      lanes.ax[l] = e.a.x();
      lanes.ay[l] = e.a.y();
      lanes.dx[l] = dir.x();
      lanes.dy[l] = dir.y();
      lanes.len[l] = len;
    }
    WalkGroup(lanes, first, used, cone, range_res, azimuth_res, sink, context);
  }
}

}  // namespace dualgrid::radar::detail
