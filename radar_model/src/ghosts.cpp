#include "ghosts.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace dualgrid::radar::detail {
namespace {

// [m] legs are shortened by this at a bounce point and at the object, so that the reflector a leg
// ends on (or a rail segment meeting it at a polyline vertex) does not hide it.
constexpr double kLegShrink = 1e-3;
// Ghost scatterers below (SNR at min_pd) / kMergeMargin are dropped: up to this many of them
// merged in one resolution cell still stay below min_pd.
constexpr double kMergeMargin = 16.0;

/// Any box or rail segment that may hide a leg which does not start at the sensor.
struct WideOccluder {
  Occluder o;
  Aabb box;
};

/// A mirror with a finite extent: the piece point + tau e, tau in [0, length], its normal turned
/// to the sensor.
struct Reflector {
  Mirror mirror;
  Vector2 e = Vector2::UnitX();  ///< unit direction along the piece
  double length = 0.0;           ///< [m]
  int id = -1;                   ///< polyline or target id (the label)
  /// Occluder codes of the reflector itself, [owner_lo, owner_hi]: a target index, or -1 - rail
  /// segment index for the (collinear) segments merged into the piece.
  int owner_lo = 0, owner_hi = 0;
  double gain = 1.0;  ///< power kept per bounce
  bool Owns(int owner) const { return owner >= owner_lo && owner <= owner_hi; }
};

/// A box of the scene within reach of the sensor (2 max_range), computed once per scan: its
/// corners (counter-clockwise: FL, RL, RR, FR), its occluder and bounding box.
struct BoxInfo {
  int index = 0;  ///< into scene.targets
  std::array<Position, 4> corners;
  Occluder occluder;
  Aabb bounds;
  double half_diagonal = 0.0;
  double distance = 0.0;  ///< sensor -> centre [m]
  double rcs = 0.0;       ///< [m^2]
};

std::vector<BoxInfo> Boxes(const SensorView& v, const Scene& scene, double radius) {
  std::vector<BoxInfo> out;
  for (std::size_t ti = 0; ti < scene.targets.size(); ++ti) {
    const Target& t = scene.targets[ti];
    BoxInfo b;
    b.half_diagonal = 0.5 * std::hypot(t.box.length, t.box.width);
    b.distance = (t.box.center - v.s).norm();
    if (b.distance - b.half_diagonal > radius || t.box.Contains(v.s)) continue;
    b.index = static_cast<int>(ti);
    b.corners = t.box.Corners();
    b.occluder.owner = b.index;
    b.occluder.is_box = true;
    b.occluder.a = t.box.center;
    // The length axis from the corners (FL - RL), saving a sine and cosine per box.
    b.occluder.axis = (b.corners[0] - b.corners[1]) / t.box.length;
    b.occluder.half_length = 0.5 * t.box.length;
    b.occluder.half_width = 0.5 * t.box.width;
    for (const Position& c : b.corners) b.bounds.Add(c);
    b.rcs = std::pow(10.0, 0.1 * t.rcs_dbsm);
    out.push_back(b);
  }
  return out;
}

bool InFieldOfView(const SensorView& v, const Position& a, const Position& b) {
  const Position local[2] = {v.to_local * (a - v.s), v.to_local * (b - v.s)};
  if (local[0].norm() < 1e-9 || local[1].norm() < 1e-9) return false;
  const Interval iv = IntervalOf(local, 2);
  return std::abs(WrapAngle(iv.center)) <= iv.half_width + 0.5 * v.params->fov;
}

/// Every box and rail segment within `radius` of the sensor, with its bounding box.
std::vector<WideOccluder> WideOccluders(const SensorView& v, const Scene& scene,
                                        const std::vector<BoxInfo>& boxes, double radius) {
  std::vector<WideOccluder> out;
  for (const BoxInfo& b : boxes) out.push_back({b.occluder, b.bounds});
  int segment_index = 0;
  for (const Polyline& line : scene.polylines) {
    for (std::size_t k = 0; k + 1 < line.points.size(); ++k, ++segment_index) {
      double t0, t1;
      const Position& p0 = line.points[k];
      const Position& p1 = line.points[k + 1];
      if (!ClipToDisc(p0, p1, v.s, radius, &t0, &t1)) continue;
      WideOccluder w;
      w.o.owner = -1 - segment_index;
      w.o.is_box = false;
      w.o.a = p0 + t0 * (p1 - p0);
      w.o.b = p0 + t1 * (p1 - p0);
      w.box.Add(w.o.a);
      w.box.Add(w.o.b);
      out.push_back(w);
    }
  }
  return out;
}

Reflector MakeReflector(const SensorView& v, const Position& a, const Position& b, int id,
                        int owner_lo, int owner_hi, double loss_db) {
  Reflector r;
  r.length = (b - a).norm();
  r.e = (b - a) / r.length;
  r.mirror.point = a;
  r.mirror.normal = Vector2(-r.e.y(), r.e.x());
  if (r.mirror.SignedDistance(v.s) < 0.0) r.mirror.normal = -r.mirror.normal;
  r.id = id;
  r.owner_lo = owner_lo;
  r.owner_hi = owner_hi;
  r.gain = std::pow(10.0, -0.1 * loss_db);
  return r;
}

/// Does p lie on the line through a and b (within 1 mm)?
bool OnLine(const Position& a, const Position& b, const Position& p) {
  const double len = (b - a).norm();
  return len > 0.0 && std::abs(Cross(b - a, p - a)) <= 1e-3 * len;
}

/// The rail pieces within `radius` of the sensor: consecutive collinear segments of a polyline
/// (a straight rail given point by point) merged into one piece, so that a bounce point is never
/// lost at a vertex and each pair is culled once.
void RailPieces(const SensorView& v, const MultipathParams& mp, const Scene& scene, double radius,
                std::vector<Reflector>* out) {
  int segment_index = 0;
  for (const Polyline& line : scene.polylines) {
    const std::size_t n = line.points.size();
    for (std::size_t k = 0; k + 1 < n;) {
      std::size_t end = k + 1;  // the piece runs from point k to point end
      while (end + 1 < n && OnLine(line.points[k], line.points[end], line.points[end + 1]) &&
             (line.points[end + 1] - line.points[end]).dot(line.points[end] - line.points[k]) > 0.0)
        ++end;
      const int first = segment_index, last = segment_index + static_cast<int>(end - k) - 1;
      segment_index = last + 1;
      const Position& p0 = line.points[k];
      const Position& p1 = line.points[end];
      k = end;
      double t0, t1;
      if (!ClipToDisc(p0, p1, v.s, radius, &t0, &t1)) continue;
      const Position a = p0 + t0 * (p1 - p0), b = p0 + t1 * (p1 - p0);
      if (!((b - a).norm() > 1e-9) || !InFieldOfView(v, a, b)) continue;
      Reflector r = MakeReflector(v, a, b, line.id, -1 - last, -1 - first, mp.rail_loss_db);
      if (r.mirror.SignedDistance(v.s) > 1e-9) out->push_back(r);
    }
  }
}

/// Rail pieces within 2 max_range (a bounce point lies within the path length) and vehicle flanks
/// turned to the sensor, all reaching into the field of view (a ghost's bounce point is seen
/// along the transmitted or received leg).
std::vector<Reflector> Reflectors(const SensorView& v, const MultipathParams& mp,
                                  const Scene& scene, const std::vector<BoxInfo>& boxes) {
  std::vector<Reflector> out;
  const double radius = 2.0 * v.params->max_range;
  if (mp.rails) RailPieces(v, mp, scene, radius, &out);
  if (!mp.vehicles) return out;
  for (const BoxInfo& info : boxes) {
    const int ti = info.index;
    const Target& t = scene.targets[ti];
    const OrientedBox& box = t.box;
    if (box.length < mp.vehicle_min_length) continue;
    const std::array<Position, 4>& c = info.corners;  // FL, RL, RR, FR: edges 0, 2 are flanks
    for (const int edge : {0, 2}) {
      const Position& a = c[edge];
      const Position& b = c[edge + 1];
      Reflector r = MakeReflector(v, a, b, t.id, ti, ti, mp.vehicle_loss_db);
      // Only the outside of a flank reflects: the sensor must face it from outside the box.
      const Vector2 outward((b - a).y(), -(b - a).x());
      if (r.mirror.normal.dot(outward) <= 0.0 || !(r.mirror.SignedDistance(v.s) > 1e-9) ||
          !InFieldOfView(v, a, b))
        continue;
      r.mirror.point_velocity = RigidPointVelocity(t.velocity, t.yaw_rate, box.center, a);
      r.mirror.yaw_rate = t.yaw_rate;
      out.push_back(r);
    }
  }
  return out;
}

/// The box's corners mirrored, in counter-clockwise order again (a mirror turns it around).
std::array<Position, 4> MirroredCorners(const Mirror& m, const std::array<Position, 4>& c) {
  return {m.Image(c[0]), m.Image(c[3]), m.Image(c[2]), m.Image(c[1])};
}

/// The SNR below which a ghost scatterer is dropped: 1/kMergeMargin of the SNR giving min_pd.
double SnrCut(const SensorView& v, const MultipathParams& mp) {
  if (!(mp.min_pd > 0.0) || mp.min_pd <= v.params->false_alarm_rate) return 0.0;
  const double root = ErfcInv(2.0 * v.params->false_alarm_rate) - ErfcInv(2.0 * mp.min_pd);
  return root > 0.0 ? root * root / kMergeMargin : 0.0;
}

/// The ghosts of one box in one mirror. Holds the leg occluders of this pair.
class PairPass {
 public:
  PairPass(const SensorView& v, const MultipathParams& mp, const Target& t, const BoxInfo& obj,
           const Reflector& r, double snr_cut, const DirectHidden& direct_hidden,
           std::vector<Scatterer>* out)
      : v_(v),
        mp_(mp),
        t_(t),
        obj_(obj),
        r_(r),
        snr_cut_(snr_cut),
        direct_hidden_(direct_hidden),
        out_(out) {}

  /// Culls the pair (side, range, SNR bound, bounce interval, field of view) and emits its
  /// ghosts. `wide`: the sensor's wide occluders; `samples`: scratch.
  void Run(const std::vector<WideOccluder>& wide, std::vector<FaceSample>& samples);

 private:
  bool Cull();
  void Gather(const std::vector<WideOccluder>& wide);
  void Emit(const Position& q_image, double rcs_share);
  bool LegsHidden(const Position& b, const Position& q);
  bool Hidden(const Position& from, const Position& to, const std::vector<const Occluder*>& list,
              bool from_sensor, bool body) const;

  const SensorView& v_;
  const MultipathParams& mp_;
  const Target& t_;
  const BoxInfo& obj_;
  const Reflector& r_;
  double snr_cut_;
  const DirectHidden& direct_hidden_;
  std::vector<Scatterer>* out_;
  bool order2_ = false, order3_ = false;
  Position b_lo_, b_hi_;  // the bounce interval's ends
  std::vector<const Occluder*> sensor_leg_, object_leg_;
  bool body_sensor_leg_ = false, body_object_leg_ = false;  // the ego's body may hide a leg
};

bool PairPass::Cull() {
  const SensorParams& p = *v_.params;
  const Mirror& m = r_.mirror;
  const Position& c = t_.box.center;
  // The object must lie wholly on the sensor's side of the mirror line.
  if (m.SignedDistance(c) <= obj_.half_diagonal)
    for (const Position& k : obj_.corners)
      if (!(m.SignedDistance(k) > 0.0)) return false;
  const double hd = obj_.half_diagonal;
  const Vector2 to_centre_image = m.Image(c) - v_.s;
  const double d_min = std::max(obj_.distance - hd, p.min_range);
  const double image_min = std::max(to_centre_image.norm() - hd, p.min_range);
  // Order 3: apparent range |q' - s|; order 2: (|q - s| + |q' - s|) / 2. The SNR bounds put the
  // whole RCS at the nearest distances.
  const double g = r_.gain;
  order3_ = mp_.max_bounces >= 3 && image_min <= p.max_range &&
            v_.model->SnrLinear(obj_.rcs * g * g, image_min) >= snr_cut_;
  order2_ = 0.5 * (d_min + image_min) <= p.max_range &&
            v_.model->SnrLinear(obj_.rcs * g, std::sqrt(d_min * image_min)) >= snr_cut_;
  if (!order2_ && !order3_) return false;
  // Bounce points of the image's corners: the rays from the sensor to the image cross the mirror
  // line in an interval (the image is convex and beyond the line). First a bound from the
  // centre's: with the image centre at depth beta beyond the sensor and alpha along the piece, a
  // point within hd of it bounces within M = hs hd (beta + |alpha|) / (beta (beta - hd)).
  const double hs = m.SignedDistance(v_.s);
  const double sigma = (v_.s - m.point).dot(r_.e);
  const double beta = -to_centre_image.dot(m.normal), alpha = to_centre_image.dot(r_.e);
  if (beta > hd) {
    const double tau = sigma + hs * alpha / beta;
    const double margin = hs * hd * (beta + std::abs(alpha)) / (beta * (beta - hd));
    if (tau + margin < 0.0 || tau - margin > r_.length) return false;
  }
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Position& k : obj_.corners) {
    const Vector2 to_image = m.Image(k) - v_.s;
    const double tau = sigma + hs / -to_image.dot(m.normal) * to_image.dot(r_.e);
    lo = std::min(lo, tau);
    hi = std::max(hi, tau);
  }
  lo = std::max(lo, 0.0);
  hi = std::min(hi, r_.length);
  if (!(lo <= hi)) return false;
  b_lo_ = m.point + lo * r_.e;
  b_hi_ = m.point + hi * r_.e;
  if (!InFieldOfView(v_, b_lo_, b_hi_)) return false;
  if (!order3_) {  // order 2 also needs the object in view (transmitted or received directly)
    Position local[4];
    for (int k = 0; k < 4; ++k) local[k] = v_.to_local * (obj_.corners[k] - v_.s);
    const Interval iv = IntervalOf(local, 4);
    if (std::abs(WrapAngle(iv.center)) > iv.half_width + 0.5 * p.fov) return false;
  }
  return true;
}

void PairPass::Gather(const std::vector<WideOccluder>& wide) {
  sensor_leg_.clear();
  object_leg_.clear();
  if (!v_.occlusion) return;
  Aabb sensor_leg, object_leg;
  sensor_leg.Add(v_.s);
  sensor_leg.Add(b_lo_);
  sensor_leg.Add(b_hi_);
  object_leg.Add(b_lo_);
  object_leg.Add(b_hi_);
  for (const Position& k : obj_.corners) object_leg.Add(k);
  body_sensor_leg_ = v_.has_body && v_.body_box.Overlaps(sensor_leg);
  body_object_leg_ = v_.has_body && v_.body_box.Overlaps(object_leg);
  for (const WideOccluder& w : wide) {
    if (r_.Owns(w.o.owner)) continue;  // the legs end on the reflector
    if (w.box.Overlaps(sensor_leg)) sensor_leg_.push_back(&w.o);
    if (w.o.owner != obj_.index && w.box.Overlaps(object_leg)) object_leg_.push_back(&w.o);
  }
}

bool PairPass::Hidden(const Position& from, const Position& to,
                      const std::vector<const Occluder*>& list, bool from_sensor, bool body) const {
  const double len = (to - from).norm();
  if (!(len > 2.0 * kLegShrink)) return false;
  const Vector2 step = kLegShrink * (to - from) / len;
  const Position a = from_sensor ? from : Position(from + step);
  const Position b = to - step;
  if (body && LengthInsideBox(v_.body, a, b) > kEgoBodyMargin) return true;
  for (const Occluder* o : list)
    if (o->is_box ? SegmentHitsBox(*o, a, b) : SegmentsIntersect(a, b, o->a, o->b)) return true;
  return false;
}

bool PairPass::LegsHidden(const Position& b, const Position& q) {
  if (!v_.occlusion) return false;
  return Hidden(v_.s, b, sensor_leg_, true, body_sensor_leg_) ||
         Hidden(b, q, object_leg_, false, body_object_leg_);
}

void PairPass::Emit(const Position& q_image, double rcs_share) {
  const SensorParams& p = *v_.params;
  const Mirror& m = r_.mirror;
  // Bounce point: where the sensor -> image ray crosses the mirror line, within the piece.
  const Vector2 to_image = q_image - v_.s;
  const Position b = v_.s + m.SignedDistance(v_.s) / -to_image.dot(m.normal) * to_image;
  const double tau = (b - m.point).dot(r_.e);
  if (tau < 0.0 || tau > r_.length) return;
  // Ranges and SNRs first (cheap): order 3 at the image, order 2 at the mean of the two legs,
  // its power falling as 1 / (d^2 d'^2), written as an RCS at the apparent range.
  const Position q = m.Image(q_image);
  const Vector2 to_q = q - v_.s;
  const double r3 = to_image.norm(), d = to_q.norm();
  const double g = r_.gain;
  const double rcs3 = rcs_share * g * g;
  const bool want3 = order3_ && r3 >= p.min_range && r3 <= p.max_range &&
                     v_.model->SnrLinear(rcs3, r3) >= snr_cut_;
  const double r2 = 0.5 * (d + r3), r2_sq = r2 * r2;
  const double rcs2 = rcs_share * g * (r2_sq * r2_sq) / (d * d * r3 * r3);
  const bool want2 = order2_ && r2 >= p.min_range && r2 <= p.max_range &&
                     v_.model->SnrLinear(rcs2, r2) >= snr_cut_;
  if (!want3 && !want2) return;
  // The bounce point must be in view: |azimuth| <= fov / 2, first as x >= r cos(fov / 2) (no
  // arc tangent for the samples that fail a cheaper test), exactly once they pass.
  const Position local_image = v_.to_local * to_image;
  if (local_image.x() < r3 * v_.cos_half_fov) return;
  const Velocity vq = RigidPointVelocity(t_.velocity, t_.yaw_rate, t_.box.center, q);
  const double rr3 = (m.ImageVelocity(q, vq) - v_.vs).dot(to_image) / r3;
  const auto rr_in_window = [&](double rr) {
    return rr >= p.min_range_rate && rr <= p.max_range_rate;
  };
  const double half_fov = 0.5 * p.fov;
  double az3 = 0.0;
  bool az3_known = false;
  const auto image_azimuth_in_view = [&] {
    if (!az3_known) az3 = std::atan2(local_image.y(), local_image.x());
    az3_known = true;
    return std::abs(az3) <= half_fov;
  };
  int legs = -1;  // -1 unknown, 0 clear, 1 hidden: tested once, when first needed
  const auto legs_clear = [&] {
    if (legs < 0) legs = LegsHidden(b, q) ? 1 : 0;
    return legs == 0;
  };
  const auto push = [&](const Position& at, const Polar& truth, double rcs, Path path,
                        int bounces) {
    Scatterer sc;
    sc.position = at;
    sc.velocity = vq;
    sc.rcs_m2 = rcs;
    sc.truth = truth;
    sc.source_id = t_.id;
    sc.path = path;
    sc.bounces = bounces;
    sc.reflector_id = r_.id;
    sc.origin = q;
    out_->push_back(sc);
  };
  // Both legs via the mirror: the image itself, with the image's velocity (its range was checked
  // with its SNR).
  if (want3 && rr_in_window(rr3) && legs_clear() && image_azimuth_in_view())
    push(q_image, {r3, az3, rr3}, rcs3, Path::kType2, 3);
  if (!want2) return;
  // One leg direct, one via the mirror: range and Doppler are the means of the two legs', the
  // azimuth the last leg's (towards the object for type 1, the image for type 2).
  const Position local_q = v_.to_local * to_q;
  if (local_q.x() < d * v_.cos_half_fov) return;
  const double rr2 = 0.5 * ((vq - v_.vs).dot(to_q) / d + rr3);
  if (!rr_in_window(rr2) || !legs_clear() || !image_azimuth_in_view()) return;
  const double azq = std::atan2(local_q.y(), local_q.x());
  if (std::abs(azq) > half_fov) return;
  if (v_.occlusion) {
    // The direct leg: the scan's own test, and the object's own box (q on a face turned away
    // from the sensor is seen only via the mirror).
    if (direct_hidden_(q, obj_.index, {d, azq, rr2})) return;
    if (SegmentHitsBox(obj_.occluder, v_.s, q - kOcclusionShrink * to_q / d)) return;
  }
  push(v_.s + (r2 / d) * to_q, {r2, azq, rr2}, rcs2, Path::kType1, 2);
  push(v_.s + (r2 / r3) * to_image, {r2, az3, rr2}, rcs2, Path::kType2, 2);
}

void PairPass::Run(const std::vector<WideOccluder>& wide, std::vector<FaceSample>& samples) {
  if (!Cull()) return;
  Gather(wide);
  const SensorParams& p = *v_.params;
  BoxScatterers(MirroredCorners(r_.mirror, obj_.corners), obj_.rcs, v_.s, p.range_resolution,
                p.azimuth_resolution, samples,
                [&](const Position& q_image, double share) { Emit(q_image, share); });
}

}  // namespace

void AddGhostScatterers(const SensorView& view, const MultipathParams& mp, const Scene& scene,
                        const DirectHidden& direct_hidden, std::vector<Scatterer>* out) {
  if (!mp.enabled || (!mp.rails && !mp.vehicles)) return;
  const SensorParams& p = *view.params;
  // Mirrors and occluders reach 2 max_range (a bounce point lies within the path length);
  // objects max_range (every ghost path is at least as long as the direct one).
  const std::vector<BoxInfo> boxes = Boxes(view, scene, 2.0 * p.max_range);
  const std::vector<Reflector> reflectors = Reflectors(view, mp, scene, boxes);
  if (reflectors.empty()) return;
  std::vector<const BoxInfo*> objects;
  for (const BoxInfo& b : boxes)
    if (b.distance - b.half_diagonal <= p.max_range) objects.push_back(&b);
  if (objects.empty()) return;
  const std::vector<WideOccluder> wide = view.occlusion
                                             ? WideOccluders(view, scene, boxes, 2.0 * p.max_range)
                                             : std::vector<WideOccluder>{};
  const double snr_cut = SnrCut(view, mp);
  std::vector<FaceSample> samples;
  for (const Reflector& r : reflectors)
    for (const BoxInfo* o : objects) {
      if (r.Owns(o->index)) continue;  // a flank does not mirror its own vehicle
      PairPass(view, mp, scene.targets[o->index], *o, r, snr_cut, direct_hidden, out)
          .Run(wide, samples);
    }
}

}  // namespace dualgrid::radar::detail
