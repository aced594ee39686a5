// Geometry shared by the direct and the multipath scatterers of the radar model (internal to
// radar_model/src): sampling faces into scatterers, occluders and segment tests.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "dualgrid/core/types.hpp"

namespace dualgrid::radar::detail {

constexpr double kMinSpacing = 0.02;       // [m] keeps sampling finite right next to a sensor
constexpr double kMaxSpacing = 1.0;        // [m] keeps long faces' shapes for occlusion
constexpr double kCornerShare = 0.5;       // corners (dihedrals) reflect strongly
constexpr double kOcclusionShrink = 1e-3;  // [m] a scatterer must not occlude itself
constexpr int kAzimuthBins = 128;          // occluder lookup by azimuth
// [m] a line of sight must run this far inside the ego's body to be blocked: the sensors sit on
// its surface, and a ray leaving the surface (or grazing it) is not hidden.
constexpr double kEgoBodyMargin = 0.05;
// [m] the body is tested shrunk by this skin: a line of sight exactly along its surface (a corner
// radar on the flank looking at a car as wide as the ego, straight ahead in its lane) grazes it.
// On the exact boundary, rounding decided: the same scene turned by 45 deg was seen, at 0 deg
// not (docs/radar.md, tests "the radar model is rotation invariant").
constexpr double kEgoBodySkin = 1e-3;
// A face is visible only if the line of sight meets it at more than this grazing angle (sine):
// a face seen exactly edge-on (a flank collinear with the sensor) returns nothing, and with it
// its far corner, hidden behind the near one (docs/radar.md step 2).
constexpr double kMinGrazingSin = 0.0087;  // sin(0.5 deg)

/// Margins of the proofs that cut a rail piece's walk (SensorScan::CutRailWalks), far above the
/// rounding of the walk's samples (~1e-12 m) and of the scan's tests: an angle [rad] added to the
/// half field of view, a distance [m] to a half-plane or line, a share of an occluder's length
/// kept from its ends, the least sine of the angle a line of sight meets an occluder at.
constexpr double kFovCutAngle = 1e-4;
constexpr double kCutDistance = 1e-3;
constexpr double kCutShare = 1e-3;
constexpr double kCutSine = 1e-2;
/// The ego body's gates (SensorScan's body regions): two segments inside the body parallel to a
/// face the sensor sits on, the first kBodyGateInset [m] inside it, the second kBodyGateGap [m]
/// beyond the first. A line of sight through both runs at least kBodyGateGap inside the body.
constexpr double kBodyGateInset = 0.01;
constexpr double kBodyGateGap = kEgoBodyMargin + 0.01;
/// A box's shadow (BoxShadow) is drawn from its corners moved this share of the way to its
/// centre, so lines of sight into the shadow cross the box's inside, not its corners.
constexpr double kShadowInset = 0.05;

/// A half-plane {q : n . q >= offset} [m], n a unit normal.
struct HalfPlane {
  Vector2 n = Vector2::UnitX();
  double offset = 0.0;
};

/// The half-plane left of the line through p along the unit direction u: Cross(u, q - p) >= 0.
inline HalfPlane LeftOf(const Position& p, const Vector2& u) {
  const Vector2 n(-u.y(), u.x());
  return {n, n.dot(p)};
}

/// A closed interval [lo, hi] of a line's parameter [m]; empty when lo > hi.
struct Span {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
};

/// Narrows `span` to the parameters t at which a + t d (d a unit direction) lies at least `depth`
/// [m] inside h.
inline void KeepInside(const HalfPlane& h, const Position& a, const Vector2& d, double depth,
                       Span* span) {
  const double c = h.n.dot(a) - h.offset - depth, k = h.n.dot(d);  // inside: c + k t >= 0
  if (k > 0.0) {
    span->lo = std::max(span->lo, -c / k);
  } else if (k < 0.0) {
    span->hi = std::min(span->hi, c / -k);
  } else if (c < 0.0) {
    span->hi = -std::numeric_limits<double>::infinity();
  }
}

/// Margin on the cosine of a half field of view [-]: far above the rounding of a cosine, a norm
/// and atan2 (~1e-15), far below any geometry that matters (1e-9 in cosine is >= 1e-9 rad).
constexpr double kFovCosMargin = 1e-9;

/// The bound FovCosBound(h) = cos(h) - kFovCosMargin used by OutsideFov, for a half field of
/// view h in [0, pi] [rad].
inline double FovCosBound(double half_fov) { return std::cos(half_fov) - kFovCosMargin; }

/// A cheap, conservative field-of-view test for a point `local` of the sensor frame at range
/// `range` = local.norm() > 0 [m]: true only when std::abs(std::atan2(local.y(), local.x())) >
/// half_fov holds for certain (x / range = cos(azimuth) lies below cos(half_fov) by more than
/// rounding can explain), so callers skip the atan2 of points it rejects and decide the rest with
/// atan2 as before. `cos_bound` = FovCosBound(half_fov).
inline bool OutsideFov(const Position& local, double range, double cos_bound) {
  return local.x() < cos_bound * range;
}

/// Angular interval seen from the sensor, stored as centre direction and cos(half width) so
/// membership is one dot product.
struct Interval {
  double center = 0.0;
  double half_width = 0.0;
};

inline Interval IntervalOf(const Position* local, int n) {
  const double a0 = std::atan2(local[0].y(), local[0].x());
  double lo = 0.0, hi = 0.0;
  for (int i = 1; i < n; ++i) {
    const double d = WrapAngle(std::atan2(local[i].y(), local[i].x()) - a0);
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
  return {WrapAngle(a0 + 0.5 * (lo + hi)), 0.5 * (hi - lo)};
}

struct Occluder {
  int owner = 0;  // target index (>= 0) or -1 - rail segment index
  bool is_box = true;
  double min_distance = 0.0;
  Vector2 center_dir = Vector2::Zero();  // sensor frame
  double cos_half_width = 1.0;
  // Box: centre, unit length axis, half extents. Segment: endpoints a, b (world).
  Position a = Position::Zero(), b = Position::Zero();
  Vector2 axis = Vector2::UnitX();
  double half_length = 0.0, half_width = 0.0;
};

inline double Cross(const Vector2& u, const Vector2& v) { return u.x() * v.y() - u.y() * v.x(); }

/// The parameter interval [t0, t1] of p + t (q - p), t in [0, 1], inside the box (Liang-Barsky
/// slab clipping in the box frame); std::nullopt if the segment misses it.
inline std::optional<std::pair<double, double>> ClipToBox(const Occluder& o, const Position& p,
                                                          const Position& q) {
  const Vector2 lateral(-o.axis.y(), o.axis.x());
  const Vector2 rp = p - o.a, d = q - p;
  const double s[2] = {rp.dot(o.axis), rp.dot(lateral)};
  const double v[2] = {d.dot(o.axis), d.dot(lateral)};
  const double h[2] = {o.half_length, o.half_width};
  double t0 = 0.0, t1 = 1.0;
  for (int i = 0; i < 2; ++i) {
    if (std::abs(v[i]) < 1e-12) {
      if (std::abs(s[i]) > h[i]) return std::nullopt;
      continue;
    }
    double ta = (-h[i] - s[i]) / v[i], tb = (h[i] - s[i]) / v[i];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return std::nullopt;
  }
  return std::pair{t0, t1};
}

/// Does the segment p -> q cross the box?
inline bool SegmentHitsBox(const Occluder& o, const Position& p, const Position& q) {
  return ClipToBox(o, p, q).has_value();
}

/// Length of the part of the segment p -> q inside the box; 0 if it misses.
inline double LengthInsideBox(const Occluder& o, const Position& p, const Position& q) {
  const auto t = ClipToBox(o, p, q);
  return t ? (t->second - t->first) * (q - p).norm() : 0.0;
}

inline bool SegmentsIntersect(const Position& p, const Position& q, const Position& a,
                              const Position& b) {
  const Vector2 r = q - p, s = b - a;
  const double denom = Cross(r, s);
  if (std::abs(denom) < 1e-12) return false;  // parallel: a thin rail cannot hide along itself
  const double t = Cross(a - p, s) / denom, u = Cross(a - p, r) / denom;
  return t >= 0.0 && t <= 1.0 && u >= 0.0 && u <= 1.0;
}

inline double PointSegmentDistance(const Position& p, const Position& a, const Position& b) {
  const Vector2 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

/// Walks the edge a -> b emitting samples (midpoint, length ds, |sin| between edge and line of
/// sight). The spacing keeps consecutive samples within half a range and half an azimuth
/// resolution cell, so every cell the edge crosses receives a scatterer, and faces spanning
/// more azimuth get more of them.
template <class Emit>
void WalkEdge(const Position& a, const Position& b, const Position& sensor, double range_res,
              double azimuth_res, Emit&& emit) {
  const double len = (b - a).norm();
  if (len <= 0.0) return;
  const Vector2 dir = (b - a) / len;
  double pos = 0.0;
  while (pos < len) {
    const Vector2 r = a + pos * dir - sensor;
    const double range = r.norm();
    double ds = kMinSpacing;
    if (range > 1e-9) {
      const double sin_phi = std::abs(Cross(dir, r)) / range,
                   cos_phi = std::abs(dir.dot(r)) / range;
      const double rate = sin_phi / (range * azimuth_res) + cos_phi / range_res;  // cells per m
      ds = std::clamp(0.5 / std::max(rate, 1e-12), kMinSpacing, kMaxSpacing);
    }
    ds = std::min(ds, len - pos);
    const Position mid = a + (pos + 0.5 * ds) * dir;
    const Vector2 rm = mid - sensor;
    const double rn = rm.norm();
    emit(mid, ds, rn > 1e-9 ? std::abs(Cross(dir, rm)) / rn : 1.0);
    pos += ds;
  }
}

/// Parameter interval [t0, t1] of a + t (b - a), t in [0, 1], inside the disc (c, radius).
inline bool ClipToDisc(const Position& a, const Position& b, const Position& c, double radius,
                       double* t0, double* t1) {
  const Vector2 d = b - a, f = a - c;
  const double qa = d.squaredNorm(), qb = 2.0 * f.dot(d), qc = f.squaredNorm() - radius * radius;
  if (qa <= 0.0) return false;
  const double disc = qb * qb - 4.0 * qa * qc;
  if (disc < 0.0) return false;
  const double sq = std::sqrt(disc);
  *t0 = std::max(0.0, (-qb - sq) / (2.0 * qa));
  *t1 = std::min(1.0, (-qb + sq) / (2.0 * qa));
  return *t0 < *t1;
}

/// An axis-aligned bounding box [m].
struct Aabb {
  double x0 = std::numeric_limits<double>::infinity(), y0 = x0;
  double x1 = -std::numeric_limits<double>::infinity(), y1 = x1;
  void Add(const Position& p) {
    x0 = std::min(x0, p.x());
    y0 = std::min(y0, p.y());
    x1 = std::max(x1, p.x());
    y1 = std::max(y1, p.y());
  }
  bool Overlaps(const Aabb& o) const {
    return x0 <= o.x1 && o.x0 <= x1 && y0 <= o.y1 && o.y0 <= y1;
  }
};

/// A sample on a box face: position and its share weight (projected width across the line of
/// sight).
struct FaceSample {
  Position q;
  double weight;
};

/// The scatterers of a box (corners `c`, counter-clockwise) seen from `s`: the corners of the
/// faces turned to it (sharing kCornerShare of `rcs` [m^2] equally) and samples along those faces
/// (sharing the rest in proportion to their projected width). Calls emit(point, rcs_share)
/// corners first, then the samples; `samples` is scratch space. Nothing when no face is turned
/// to the sensor.
template <class Emit>
void BoxScatterers(const std::array<Position, 4>& c, double rcs, const Position& s,
                   double range_res, double azimuth_res, std::vector<FaceSample>& samples,
                   Emit&& emit) {
  bool corner_visible[4] = {false, false, false, false};
  samples.clear();
  double edge_weight = 0.0;
  for (int e = 0; e < 4; ++e) {
    const Position& a = c[e];
    const Position& b = c[(e + 1) % 4];
    const Vector2 normal(b.y() - a.y(), a.x() - b.x());  // outward for a CCW polygon
    const Vector2 to_sensor = s - 0.5 * (a + b);
    const double nn = normal.norm() * to_sensor.norm();
    if (!(nn > 0.0) || normal.dot(to_sensor) <= kMinGrazingSin * nn) continue;
    corner_visible[e] = corner_visible[(e + 1) % 4] = true;
    WalkEdge(a, b, s, range_res, azimuth_res, [&](const Position& q, double ds, double sin_phi) {
      // Share ~ projected width across the line of sight.
      samples.push_back({q, ds * sin_phi});
      edge_weight += ds * sin_phi;
    });
  }
  const int n_corners = static_cast<int>(std::count(corner_visible, corner_visible + 4, true));
  if (n_corners == 0) return;
  const double corner_share = edge_weight > 0.0 ? kCornerShare : 1.0;
  for (int k = 0; k < 4; ++k)
    if (corner_visible[k]) emit(c[k], rcs * corner_share / n_corners);
  if (edge_weight > 0.0)
    for (const FaceSample& smp : samples)
      emit(smp.q, rcs * (1.0 - kCornerShare) * smp.weight / edge_weight);
}

}  // namespace dualgrid::radar::detail
