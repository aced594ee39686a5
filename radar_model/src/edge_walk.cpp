#include "edge_walk.hpp"

#include <algorithm>
#include <cassert>

#include <hwy/highway.h>

#include "scan_geometry.hpp"

namespace dualgrid::radar::detail {
namespace {

namespace hn = hwy::HWY_NAMESPACE;
using DD = hn::ScalableTag<double>;  // the pinned SSE4 target: two lanes, no FMA
using VD = hn::Vec<DD>;
static_assert(HWY_TARGET == HWY_SSE4, "the radar's SIMD target is pinned to SSE4");

constexpr int kLanes = 2;                  // doubles per SSE4 vector
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

void WalkGroup(const Lanes& lanes, int used, const Position& sensor, double range_res,
               double azimuth_res, std::vector<EdgeSample>* const* out) {
  const DD d;
  assert(hn::Lanes(d) == kLanes);
  const VD sx = hn::Set(d, sensor.x()), sy = hn::Set(d, sensor.y());
  const VD rr = hn::Set(d, range_res), ar = hn::Set(d, azimuth_res), half = hn::Set(d, 0.5);
  VD pos[kVectors];
  for (VD& p : pos) p = hn::Zero(d);
  alignas(16) double was[kGroup], qx[kGroup], qy[kGroup], step[kGroup];
  for (;;) {
    bool any = false;
    for (int k = 0; k < kVectors; ++k) {
      const int o = k * kLanes;
      const VD ax = hn::Load(d, lanes.ax + o), ay = hn::Load(d, lanes.ay + o);
      const VD dx = hn::Load(d, lanes.dx + o), dy = hn::Load(d, lanes.dy + o);
      const VD len = hn::Load(d, lanes.len + o);
      const auto active = hn::Lt(pos[k], len);
      hn::Store(pos[k], d, was + o);
      if (hn::AllFalse(d, active)) continue;
      any = true;
      const VD ds = Spacing(d, ax, ay, dx, dy, len, pos[k], sx, sy, rr, ar);
      const VD t = hn::Add(pos[k], hn::Mul(half, ds));
      hn::Store(hn::Add(ax, hn::Mul(t, dx)), d, qx + o);
      hn::Store(hn::Add(ay, hn::Mul(t, dy)), d, qy + o);
      hn::Store(ds, d, step + o);
      pos[k] = hn::IfThenElse(active, hn::Add(pos[k], ds), pos[k]);
    }
    if (!any) return;
    for (int l = 0; l < used; ++l)
      if (was[l] < lanes.len[l]) out[l]->push_back({Position(qx[l], qy[l]), step[l]});
  }
}

}  // namespace

void WalkEdges(const Edge* edges, int n, const Position& sensor, double range_res,
               double azimuth_res, std::vector<std::vector<EdgeSample>>* samples) {
  if (samples->size() < static_cast<std::size_t>(n)) samples->resize(n);
  for (int first = 0; first < n; first += kGroup) {
    const int used = std::min(kGroup, n - first);
    Lanes lanes;
    std::vector<EdgeSample>* out[kGroup] = {};
    for (int l = 0; l < used; ++l) {
      const Edge& e = edges[first + l];
      out[l] = &(*samples)[first + l];
      out[l]->clear();
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
    WalkGroup(lanes, used, sensor, range_res, azimuth_res, out);
  }
}

}  // namespace dualgrid::radar::detail
