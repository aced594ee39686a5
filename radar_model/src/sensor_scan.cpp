#include "sensor_scan.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "ghosts.hpp"

namespace dualgrid::radar::detail {
namespace {

// Puts (*out)[begin, end) in the order of piece_of (one entry each, values in [0, pieces)),
// stably: the scatterers of piece 0 first, each piece's in the order they came.
void GroupByPiece(std::vector<Scatterer>* out, std::size_t begin, const std::vector<int>& piece_of,
                  int pieces, ScanScratch& scratch) {
  assert(out->size() - begin == piece_of.size());
  if (std::is_sorted(piece_of.begin(), piece_of.end())) return;
  std::vector<int>& starts = scratch.piece_starts;
  starts.assign(pieces + 1, 0);
  for (const int k : piece_of) ++starts[k + 1];
  for (int k = 0; k < pieces; ++k) starts[k + 1] += starts[k];
  std::vector<Scatterer>& buffer = scratch.rail_buffer;
  buffer.resize(piece_of.size());
  for (std::size_t i = 0; i < piece_of.size(); ++i)
    buffer[starts[piece_of[i]]++] = (*out)[begin + i];
  std::copy(buffer.begin(), buffer.end(), out->begin() + static_cast<std::ptrdiff_t>(begin));
}

}  // namespace

TargetGeometry::TargetGeometry(const Target& t)
    : corners(t.box.Corners()),
      inside(t.box),
      half_diagonal(0.5 * std::hypot(t.box.length, t.box.width)),
      axis(UnitVector(t.box.yaw)),
      rcs_m2(std::pow(10.0, 0.1 * t.rcs_dbsm)) {}

void ComputeTargetGeometry(const Scene& scene, std::vector<TargetGeometry>* out) {
  out->clear();
  out->reserve(scene.targets.size());
  for (const Target& t : scene.targets) out->emplace_back(t);
}

SensorScan::SensorScan(const SensorParams& p, const SensorModel& model, const ModelOptions& options,
                       const EgoMotion& ego, const Scene& scene,
                       const std::vector<TargetGeometry>& targets, ScanScratch& scratch)
    : p_(p),
      model_(model),
      options_(options),
      ego_(ego),
      scene_(scene),
      targets_(targets),
      scratch_(scratch) {
  assert(targets.size() == scene.targets.size());
  const Pose2 pose = SensorWorldPose(p, ego.pose);
  s_ = pose.position;
  vs_ = RigidPointVelocity(ego.velocity, ego.yaw_rate, ego.pose.position, s_);
  half_fov_ = 0.5 * p.fov;
  // Pose2::ToLocal recomputes cos/sin per call; this is the per-scatterer hot path.
  to_local_ = Rotation(pose.yaw).transpose();
  bin_width_ = p.fov / kAzimuthBins;
  // Most walked rail samples lie outside the field of view (a rail piece is walked whole once
  // some of it is in view): those that OutsideFov rejects skip the atan2 (the same outcome).
  fov_cos_bound_ = FovCosBound(half_fov_);
  // The ego's own body: checked for every scatterer (the sensors sit on it, so its angular
  // interval spans up to a half turn and does not fit the azimuth bins).
  has_body_ =
      options.occlusion && ego.length > 2.0 * kEgoBodySkin && ego.width > 2.0 * kEgoBodySkin;
  body_.a = ego.pose.position;
  body_.axis = UnitVector(ego.pose.yaw);
  body_.half_length = 0.5 * ego.length - kEgoBodySkin;
  body_.half_width = 0.5 * ego.width - kEgoBodySkin;
  cone_.position = s_;
  cone_.to_local = to_local_;
  cone_.min_range = p.min_range;
  cone_.max_range = p.max_range;
  cone_.fov_cos_bound = fov_cos_bound_;
  cone_.range_res = p.range_resolution;
  cone_.azimuth_res = p.azimuth_resolution;

  // 1. Occluders and candidate sources within range and field of view, culled cheaply first.
  scratch.occluders.clear();
  CullTargets();
  CullRails();
  FillBins();
  CutRailWalks();
  // 2. Boxes: samples on the faces facing the sensor plus their corners, sharing the RCS.
  scratch.scatterers.clear();
  AddBoxes();
  rail_begin_ = scratch.scatterers.size();
  scratch.piece_of.clear();
}

bool SensorScan::InFov(const Interval& iv) const {
  return std::abs(WrapAngle(iv.center)) <= iv.half_width + half_fov_;
}

void SensorScan::CullTargets() {
  std::vector<int>& candidates = scratch_.candidate_targets;
  candidates.clear();
  for (std::size_t ti = 0; ti < scene_.targets.size(); ++ti) {
    const OrientedBox& box = scene_.targets[ti].box;
    const TargetGeometry& g = targets_[ti];
    const double center_dist = (box.center - s_).norm();
    if (center_dist - g.half_diagonal > p_.max_range || g.inside.Contains(s_)) continue;
    Position local[4];
    for (int k = 0; k < 4; ++k) local[k] = LocalOf(g.corners[k]);
    const Interval iv = IntervalOf(local, 4);
    if (!InFov(iv)) continue;
    candidates.push_back(static_cast<int>(ti));
    Occluder o;
    o.owner = static_cast<int>(ti);
    o.is_box = true;
    o.min_distance = std::max(0.0, center_dist - g.half_diagonal);
    o.center_dir = UnitVector(iv.center);
    o.cos_half_width = std::cos(iv.half_width);
    o.a = box.center;
    o.axis = g.axis;
    o.half_length = 0.5 * box.length;
    o.half_width = 0.5 * box.width;
    scratch_.occluders.push_back(o);
  }
}

void SensorScan::CullRails() {
  std::vector<RailPiece>& rail_pieces = scratch_.rail_pieces;
  rail_pieces.clear();
  int segment_index = 0;
  for (std::size_t li = 0; li < scene_.polylines.size(); ++li) {
    const std::vector<Position>& pts = scene_.polylines[li].points;
    for (std::size_t k = 0; k + 1 < pts.size(); ++k, ++segment_index) {
      double t0, t1;
      if (!ClipToDisc(pts[k], pts[k + 1], s_, p_.max_range, &t0, &t1)) continue;
      const Position a = pts[k] + t0 * (pts[k + 1] - pts[k]);
      const Position b = pts[k] + t1 * (pts[k + 1] - pts[k]);
      const Position local[2] = {LocalOf(a), LocalOf(b)};
      if (local[0].norm() < 1e-9 || local[1].norm() < 1e-9) continue;
      const Interval iv = IntervalOf(local, 2);
      if (!InFov(iv)) continue;
      rail_pieces.push_back({static_cast<int>(li), a, b, segment_index,
                             std::pow(10.0, 0.1 * scene_.polylines[li].rcs_dbsm_per_metre)});
      Occluder o;
      o.owner = -1 - segment_index;
      o.is_box = false;
      o.min_distance = PointSegmentDistance(s_, a, b);
      o.center_dir = UnitVector(iv.center);
      o.cos_half_width = std::cos(iv.half_width);
      o.a = a;
      o.b = b;
      scratch_.occluders.push_back(o);
    }
  }
}

// Azimuth bins over the field of view listing the occluders whose interval overlaps them.
void SensorScan::FillBins() {
  if (!options_.occlusion) return;
  std::vector<std::vector<int>>& bins = scratch_.bins;
  bins.resize(kAzimuthBins);
  for (std::vector<int>& bin : bins) bin.clear();
  for (std::size_t k = 0; k < scratch_.occluders.size(); ++k) {
    const Occluder& o = scratch_.occluders[k];
    const double c = std::atan2(o.center_dir.y(), o.center_dir.x());
    const double hw = std::acos(std::clamp(o.cos_half_width, -1.0, 1.0));
    // The interval may wrap through +-pi; try it shifted by a turn either way (it is narrower
    // than a half turn, so no bin is listed twice). One bin of slack on each side.
    for (const double shift : {-2.0 * kPi, 0.0, 2.0 * kPi}) {
      const int first = static_cast<int>(std::floor((c + shift - hw + half_fov_) / bin_width_)) - 1;
      const int last = static_cast<int>(std::floor((c + shift + hw + half_fov_) / bin_width_)) + 1;
      for (int bi = std::max(first, 0); bi <= std::min(last, kAzimuthBins - 1); ++bi)
        bins[bi].push_back(static_cast<int>(k));
    }
  }
}

// Does rail occluder `o` hide every point of the segment p0 -> p1 in BehindOthers (o.owner is not
// the points' owner)? Sufficient, with margins far above rounding: s and the segment lie on
// opposite sides of o's line, the segment more than the occlusion shrink plus kCutDistance beyond
// it, so each shrunk line of sight crosses the line strictly inside (0 < t < 1); the lines of
// sight to p0 and p1 meet o at a parameter u inside [kCutShare, 1 - kCutShare] at an angle whose
// sine is at least kCutSine, and so do those to every point between (the direction turns
// monotonically along the segment, by less than a half turn). Such a point's direction lies
// inside o's angular interval (the dot test and the azimuth bins, which have a bin of slack, list
// o), its range exceeds o.min_distance, and SegmentsIntersect finds the crossing.
bool SensorScan::HidesWhole(const Occluder& o, const Position& p0, const Position& p1) const {
  const Vector2 sv = o.b - o.a;
  const double len = sv.norm();
  if (o.is_box || !(len >= 1e-2)) return false;
  const double side_s = Cross(sv, s_ - o.a) / len;
  if (!(std::abs(side_s) >= kCutDistance)) return false;
  for (const Position& p : {p0, p1}) {
    if (!(Cross(sv, p - o.a) / len * (side_s > 0.0 ? -1.0 : 1.0) >=
          kOcclusionShrink + kCutDistance))
      return false;
    const Vector2 r = p - s_;
    const double denom = Cross(sv, r);
    if (!(std::abs(denom) >= kCutSine * len * r.norm())) return false;
    const double u = Cross(s_ - o.a, r) / denom;
    if (!(u >= kCutShare && u <= 1.0 - kCutShare)) return false;
  }
  return true;
}

// The field of view: the wedge |azimuth| <= h' (h' = half_fov + kFovCutAngle < pi / 2) is the
// intersection of two half-planes; a point more than kCutDistance outside either lies outside it,
// so OutsideFov (margin 1e-9 in cosine, rounding ~1e-15 of the range) rejects it. The body: for
// each face of the ego's box the sensor sits on (or beyond), two gates inside the box parallel to
// the face (kBodyGateInset and kBodyGateInset + kBodyGateGap deep, the face's length less
// kCutDistance); a point beyond the second gate whose line of sight passes between both gates'
// ends crosses both inside the box, so its line of sight runs at least kBodyGateGap >
// kEgoBodyMargin inside the body and BehindBody rejects it. Those points form the intersection
// of five half-planes: beyond the second gate, and between the lines from s through each gate's
// ends.
RejectedRegions MakeRejectedRegions(const Position& s, const Matrix2& to_local, double half_fov,
                                    const Occluder* body) {
  RejectedRegions out;
  const double h = half_fov + kFovCutAngle;
  if (half_fov >= 1e-3 && h <= 0.5 * kPi - 1e-3) {
    const Vector2 boresight = to_local.row(0).transpose(), left = to_local.row(1).transpose();
    const double sin_h = std::sin(h), cos_h = std::cos(h);
    for (const double side : {-1.0, 1.0}) {  // inside the wedge: (q - s) . n >= 0
      const Vector2 n = sin_h * boresight + side * cos_h * left;
      out.fov_outside[out.fov++] = {-n, -n.dot(s)};
    }
  }
  if (!body) return out;
  const Vector2 axis = body->axis, lateral(-axis.y(), axis.x());
  const struct {
    Vector2 n;  // outward normal
    double h;   // half extent along n [m]
    Vector2 along;
    double e;  // half extent along `along` [m]
  } faces[4] = {{axis, body->half_length, lateral, body->half_width},
                {-axis, body->half_length, lateral, body->half_width},
                {lateral, body->half_width, axis, body->half_length},
                {-lateral, body->half_width, axis, body->half_length}};
  for (const auto& f : faces) {
    const double g1 = f.h - kBodyGateInset, g2 = g1 - kBodyGateGap, e = f.e - kCutDistance;
    if (!(f.n.dot(s - body->a) >= g1 + kCutDistance && g2 >= -f.h && e > 0.0)) continue;
    std::array<HalfPlane, 5>& region = out.behind_body[out.body++];
    region[0] = {-f.n, -f.n.dot(body->a) - g2};  // beyond the second gate: n . (q - c) <= g2
    int k = 1;
    for (const double g : {g1, g2}) {
      const Position mid = body->a + g * f.n;
      const Vector2 u0 = (mid + e * f.along - s).normalized();
      const Vector2 u1 = (mid - e * f.along - s).normalized();
      const double turn = Cross(u0, u1) > 0.0 ? 1.0 : -1.0;
      region[k++] = LeftOf(s, turn * u0);  // between the lines through the gate's ends
      region[k++] = LeftOf(s, -turn * u1);
    }
  }
  return out;
}

std::optional<std::array<HalfPlane, 3>> BoxShadow(const Position& s,
                                                  const std::array<Position, 4>& corners) {
  const Position centre = 0.25 * (corners[0] + corners[1] + corners[2] + corners[3]);
  std::array<Position, 4> c;
  for (int k = 0; k < 4; ++k) c[k] = corners[k] + kShadowInset * (centre - corners[k]);
  // The outermost corners: all others lie counter-clockwise of `right`, clockwise of `left`.
  int right = -1, left = -1;
  for (int i = 0; i < 4; ++i) {
    bool is_right = true, is_left = true;
    for (int j = 0; j < 4; ++j) {
      const double turn = Cross(c[i] - s, c[j] - s);
      is_right = is_right && turn >= 0.0;
      is_left = is_left && turn <= 0.0;
    }
    if (is_right && right < 0) right = i;
    if (is_left && left < 0) left = i;
  }
  if (right < 0 || left < 0 || !(Cross(c[right] - s, c[left] - s) > 0.0)) return std::nullopt;
  if (!(Cross(c[left] - c[right], s - c[right]) > kCutDistance * (c[left] - c[right]).norm()))
    return std::nullopt;  // s must lie clear of the two corners' segment, on its left
  // Beyond the segment (on its right) by the occlusion shrink as well: the shrunk line of sight
  // still crosses it.
  HalfPlane beyond = LeftOf(c[right], -(c[left] - c[right]).normalized());
  beyond.offset += kOcclusionShrink;
  return std::array<HalfPlane, 3>{LeftOf(s, (c[right] - s).normalized()),
                                  LeftOf(s, -(c[left] - s).normalized()), beyond};
}

// A piece's walk_begin, walk_end and skip: the spans of samples that lie in a rejected region
// (kCutDistance deep; the spans are computed twice as deep, so rounding of the spans and of the
// samples' positions, ~1e-12 m, stays inside): outside the view, behind the body, in the shadow
// of a candidate box (BehindOthers lists it: its interval holds the shadow's directions, its
// min_distance is nearer, SegmentHitsBox finds the crossing). Their union's stretches at the ends
// are not walked or not handed on, its longest stretch between is skipped. Then a piece that
// another rail hides in all of the rest is not walked (the median barrier hides the far rail).
void SensorScan::CutRailWalk(RailPiece& piece) {
  const double len = (piece.b - piece.a).norm();
  if (!(len > 0.0)) return;
  const Vector2 d = (piece.b - piece.a) / len;
  const double depth = 2.0 * kCutDistance;
  std::vector<Span>& spans = scratch_.spans;
  spans.clear();
  for (int i = 0; i < rejected_.fov; ++i) {
    spans.emplace_back();
    KeepInside(rejected_.fov_outside[i], piece.a, d, depth, &spans.back());
  }
  for (int r = 0; r < rejected_.body; ++r) {
    spans.emplace_back();
    for (const HalfPlane& h : rejected_.behind_body[r])
      KeepInside(h, piece.a, d, depth, &spans.back());
  }
  for (const std::array<HalfPlane, 3>& shadow : scratch_.shadows) {
    spans.emplace_back();
    for (const HalfPlane& h : shadow) KeepInside(h, piece.a, d, depth, &spans.back());
  }
  std::erase_if(spans,
                [&](const Span& sp) { return !(sp.lo <= sp.hi && sp.hi >= 0.0 && sp.lo <= len); });
  std::sort(spans.begin(), spans.end(), [](const Span& x, const Span& y) { return x.lo < y.lo; });
  double begin = 0.0, end = len;
  Span skip = piece.skip;
  for (std::size_t i = 0; i < spans.size();) {  // the union's stretches, in order
    Span u = spans[i];
    for (++i; i < spans.size() && spans[i].lo <= u.hi; ++i) u.hi = std::max(u.hi, spans[i].hi);
    if (u.lo <= 0.0) {
      begin = std::max(begin, u.hi);
    } else if (u.hi >= len) {
      end = std::min(end, u.lo);
    } else if (!(skip.hi - skip.lo >= u.hi - u.lo)) {
      skip = u;
    }
  }
  piece.walk_begin = begin;
  piece.walk_end = end < len ? end : std::numeric_limits<double>::infinity();
  piece.skip = skip;
  if (!(begin < end)) {
    piece.walk_end = 0.0;
    return;
  }
  if (!options_.occlusion) return;
  const Position first = piece.a + begin * d, last = end < len ? piece.a + end * d : piece.b;
  for (const Occluder& o : scratch_.occluders)
    if (o.owner != -1 - piece.segment && HidesWhole(o, first, last)) {
      piece.walk_end = 0.0;
      return;
    }
}

void SensorScan::CutRailWalks() {
  rejected_ = MakeRejectedRegions(s_, to_local_, half_fov_, has_body_ ? &body_ : nullptr);
  scratch_.shadows.clear();
  if (options_.occlusion)
    for (const Occluder& o : scratch_.occluders)
      if (o.is_box)
        if (const auto shadow = BoxShadow(s_, targets_[o.owner].corners))
          scratch_.shadows.push_back(*shadow);
  for (RailPiece& piece : scratch_.rail_pieces) CutRailWalk(piece);
}

void SensorScan::AddBoxes() {
  for (const int ti : scratch_.candidate_targets) {
    const Target& t = scene_.targets[ti];
    BoxScatterers(targets_[ti].corners, targets_[ti].rcs_m2, s_, p_.range_resolution,
                  p_.azimuth_resolution, scratch_.samples,
                  [&](const Position& q, double rcs_share) {
                    Consider(q, RigidPointVelocity(t.velocity, t.yaw_rate, t.box.center, q),
                             rcs_share, t.id, ti);
                  });
  }
}

// The ego's body hides q (needs no azimuth).
bool SensorScan::BehindBody(const Position& q) const {
  return has_body_ && LengthInsideBox(body_, s_, q) > kEgoBodyMargin;
}

// Another occluder hides q (the azimuth bins'); with BehindBody, the scan's occlusion test.
bool SensorScan::BehindOthers(const Position& q, int owner, const Polar& truth) const {
  const Vector2 dir_local = LocalOf(q) / truth.range;
  const Position end = q - kOcclusionShrink * (q - s_) / truth.range;
  const int bi =
      std::clamp(static_cast<int>((truth.azimuth + half_fov_) / bin_width_), 0, kAzimuthBins - 1);
  for (const int k : scratch_.bins[bi]) {
    const Occluder& o = scratch_.occluders[k];
    if (o.owner == owner || o.min_distance >= truth.range) continue;
    if (dir_local.dot(o.center_dir) < o.cos_half_width - 1e-12) continue;
    if (o.is_box ? SegmentHitsBox(o, s_, end) : SegmentsIntersect(s_, end, o.a, o.b)) return true;
  }
  return false;
}

// A point q kept by the first tests (range and field of view), with its local coordinates and
// range: the azimuth, the window and occlusion decide. True when it became a scatterer. The tests
// are pure and all must pass, so their order does not change the outcome: the ego's body first
// (it needs no azimuth, and a corner radar's view along the car is mostly behind it), then the
// atan2 and the rest.
bool SensorScan::ConsiderKept(const Position& q, const Position& local, double range,
                              const Velocity& v, double rcs_m2, int source_id, int owner) {
  if (BehindBody(q)) return false;
  Scatterer sc;
  sc.truth.range = range;
  sc.truth.azimuth = std::atan2(local.y(), local.x());
  if (std::abs(sc.truth.azimuth) > half_fov_) return false;
  sc.truth.range_rate = (v - vs_).dot(q - s_) / sc.truth.range;
  if (!model_.InWindow(sc.truth) || (options_.occlusion && BehindOthers(q, owner, sc.truth)))
    return false;
  sc.position = q;
  sc.velocity = v;
  sc.rcs_m2 = rcs_m2;
  sc.source_id = source_id;
  sc.origin = q;
  scratch_.scatterers.push_back(sc);
  return true;
}

void SensorScan::Consider(const Position& q, const Velocity& v, double rcs_m2, int source_id,
                          int owner) {
  const Position local = LocalOf(q);
  const double range = local.norm();
  if (range < p_.min_range || range > p_.max_range) return;
  if (OutsideFov(local, range, fov_cos_bound_)) return;
  ConsiderKept(q, local, range, v, rcs_m2, source_id, owner);
}

void SensorScan::ConsiderRailSample(int k, const EdgeSample& e) {
  const RailPiece& piece = scratch_.rail_pieces[k];
  if (ConsiderKept(e.q, e.local, e.range, Velocity::Zero(), piece.rcs_per_m * e.ds,
                   scene_.polylines[piece.polyline].id, -1 - piece.segment))
    scratch_.piece_of.push_back(k);
}

void SensorScan::FinishRails() {
  GroupByPiece(&scratch_.scatterers, rail_begin_, scratch_.piece_of,
               static_cast<int>(scratch_.rail_pieces.size()), scratch_);
}

void SensorScan::AddGhosts() {
  if (!options_.multipath.enabled) return;
  SensorView view;
  view.params = &p_;
  view.model = &model_;
  view.s = s_;
  view.vs = vs_;
  view.to_local = to_local_;
  view.cos_half_fov = std::cos(half_fov_);
  view.occlusion = options_.occlusion;
  view.has_body = has_body_;
  view.body = body_;
  if (has_body_)
    for (const Position& c :
         OrientedBox{ego_.pose.position, ego_.pose.yaw, ego_.length, ego_.width}.Corners())
      view.body_box.Add(c);
  const auto occluded = [this](const Position& q, int owner, const Polar& truth) {
    return options_.occlusion && (BehindBody(q) || BehindOthers(q, owner, truth));
  };
  AddGhostScatterers(view, options_.multipath, scene_, occluded, &scratch_.scatterers);
}

void ScanRails(std::span<SensorScan* const> scans, RailWalkScratch& scratch, bool cut) {
  std::vector<Edge>& edges = scratch.edges;
  std::vector<SensorCone>& cones = scratch.cones;
  std::vector<std::pair<int, int>>& owner_of = scratch.owner_of;
  cones.clear();
  edges.clear();
  owner_of.clear();
  for (std::size_t j = 0; j < scans.size(); ++j) {
    cones.push_back(scans[j]->cone());
    const std::vector<RailPiece>& pieces = scans[j]->rail_pieces();
    for (std::size_t k = 0; k < pieces.size(); ++k) {
      if (cut && pieces[k].walk_end == 0.0) continue;
      if (cut)
        edges.push_back({pieces[k].a, pieces[k].b, static_cast<int>(j), pieces[k].walk_end,
                         pieces[k].walk_begin, pieces[k].skip.lo, pieces[k].skip.hi});
      else
        edges.push_back({pieces[k].a, pieces[k].b, static_cast<int>(j)});
      owner_of.emplace_back(static_cast<int>(j), static_cast<int>(k));
    }
  }
  auto sink = [&](int edge, const EdgeSample& e) {
    const auto [scan, piece] = owner_of[edge];
    scans[scan]->ConsiderRailSample(piece, e);
  };
  WalkEdges(edges.data(), static_cast<int>(edges.size()), cones.data(), sink);
  for (SensorScan* scan : scans) scan->FinishRails();
}

}  // namespace dualgrid::radar::detail
