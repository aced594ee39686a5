#include "dualgrid/radar_model/radar_model.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <utility>

namespace dualgrid::radar {
namespace {

constexpr int kCellBits = 20;              // per packed cell-index dimension and per RNG index
constexpr int kMaxSensors = 1 << 12;       // sensor << kCellBits must fit the 32-bit RNG index
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

/// Angular interval seen from the sensor, stored as centre direction and cos(half width) so
/// membership is one dot product.
struct Interval {
  double center = 0.0;
  double half_width = 0.0;
};

Interval IntervalOf(const Position* local, int n) {
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

double Cross(const Vector2& u, const Vector2& v) { return u.x() * v.y() - u.y() * v.x(); }

/// The parameter interval [t0, t1] of p + t (q - p), t in [0, 1], inside the box (Liang-Barsky
/// slab clipping in the box frame); std::nullopt if the segment misses it.
std::optional<std::pair<double, double>> ClipToBox(const Occluder& o, const Position& p,
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
bool SegmentHitsBox(const Occluder& o, const Position& p, const Position& q) {
  return ClipToBox(o, p, q).has_value();
}

/// Length of the part of the segment p -> q inside the box; 0 if it misses.
double LengthInsideBox(const Occluder& o, const Position& p, const Position& q) {
  const auto t = ClipToBox(o, p, q);
  return t ? (t->second - t->first) * (q - p).norm() : 0.0;
}

bool SegmentsIntersect(const Position& p, const Position& q, const Position& a, const Position& b) {
  const Vector2 r = q - p, s = b - a;
  const double denom = Cross(r, s);
  if (std::abs(denom) < 1e-12) return false;  // parallel: a thin rail cannot hide along itself
  const double t = Cross(a - p, s) / denom, u = Cross(a - p, r) / denom;
  return t >= 0.0 && t <= 1.0 && u >= 0.0 && u <= 1.0;
}

double PointSegmentDistance(const Position& p, const Position& a, const Position& b) {
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
bool ClipToDisc(const Position& a, const Position& b, const Position& c, double radius, double* t0,
                double* t1) {
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

struct SensorGeometry {
  Pose2 pose;
  Velocity velocity;  // over ground, including the yaw-rate lever arm
};

}  // namespace

RadarModel::RadarModel(std::vector<SensorParams> sensors, ModelOptions options, std::uint64_t seed)
    : params_(std::move(sensors)), options_(options), seed_(seed) {
  if (params_.size() >= static_cast<std::size_t>(kMaxSensors))
    throw std::invalid_argument("RadarModel: at most 4095 sensors");
  models_.reserve(params_.size());
  for (std::size_t i = 0; i < params_.size(); ++i) {
    std::string error;
    if (!params_[i].IsValid(&error))
      throw std::invalid_argument("radar sensor " + std::to_string(i) + " ('" + params_[i].name +
                                  "'): " + error);
    models_.emplace_back(params_[i]);
  }
}

void RadarModel::CheckSensor(int sensor) const {
  if (sensor < 0 || sensor >= static_cast<int>(params_.size()))
    throw std::out_of_range("RadarModel: no sensor " + std::to_string(sensor));
}

Pose2 RadarModel::SensorPose(int sensor, const Pose2& ego_pose) const {
  CheckSensor(sensor);
  return SensorWorldPose(params_[sensor], ego_pose);
}

std::vector<Pose2> RadarModel::SensorPoses(const Pose2& ego_pose) const {
  std::vector<Pose2> poses;
  for (const SensorParams& p : params_) poses.push_back(SensorWorldPose(p, ego_pose));
  return poses;
}

std::vector<int> RadarModel::SensorsDue(double time, double step_length) const {
  if (!(step_length > 0.0)) throw std::invalid_argument("SensorsDue: step_length must be > 0");
  std::vector<int> due;
  for (std::size_t i = 0; i < params_.size(); ++i) {
    const double period = params_[i].update_period;
    const double now = std::floor(time / period + 1e-9);
    const double before = std::floor((time - step_length) / period + 1e-9);
    if (now > before) due.push_back(static_cast<int>(i));
  }
  return due;
}

std::vector<Scatterer> RadarModel::VisibleScatterers(int sensor, const EgoMotion& ego,
                                                     const Scene& scene) const {
  CheckSensor(sensor);
  const SensorParams& p = params_[sensor];
  const SensorModel& model = models_[sensor];
  const Pose2 pose = SensorWorldPose(p, ego.pose);
  const Position s = pose.position;
  const Velocity vs = RigidPointVelocity(ego.velocity, ego.yaw_rate, ego.pose.position, s);
  const double half_fov = 0.5 * p.fov;
  // Pose2::ToLocal recomputes cos/sin per call; this is the per-scatterer hot path.
  const Matrix2 to_local = Rotation(pose.yaw).transpose();
  const auto local_of = [&](const Position& q) -> Position { return to_local * (q - s); };
  const auto in_fov = [&](const Interval& iv) {
    return std::abs(WrapAngle(iv.center)) <= iv.half_width + half_fov;
  };

  // 1. Occluders and candidate sources within range and field of view, culled cheaply first.
  std::vector<Occluder> occluders;
  std::vector<int> candidate_targets;
  for (std::size_t ti = 0; ti < scene.targets.size(); ++ti) {
    const OrientedBox& box = scene.targets[ti].box;
    const double half_diag = 0.5 * std::hypot(box.length, box.width);
    const double center_dist = (box.center - s).norm();
    if (center_dist - half_diag > p.max_range || box.Contains(s)) continue;
    const std::array<Position, 4> corners = box.Corners();
    Position local[4];
    for (int k = 0; k < 4; ++k) local[k] = local_of(corners[k]);
    const Interval iv = IntervalOf(local, 4);
    if (!in_fov(iv)) continue;
    candidate_targets.push_back(static_cast<int>(ti));
    Occluder o;
    o.owner = static_cast<int>(ti);
    o.is_box = true;
    o.min_distance = std::max(0.0, center_dist - half_diag);
    o.center_dir = UnitVector(iv.center);
    o.cos_half_width = std::cos(iv.half_width);
    o.a = box.center;
    o.axis = UnitVector(box.yaw);
    o.half_length = 0.5 * box.length;
    o.half_width = 0.5 * box.width;
    occluders.push_back(o);
  }
  struct RailPiece {
    int polyline;
    Position a, b;
    int segment;
  };
  std::vector<RailPiece> rail_pieces;
  int segment_index = 0;
  for (std::size_t li = 0; li < scene.polylines.size(); ++li) {
    const std::vector<Position>& pts = scene.polylines[li].points;
    for (std::size_t k = 0; k + 1 < pts.size(); ++k, ++segment_index) {
      double t0, t1;
      if (!ClipToDisc(pts[k], pts[k + 1], s, p.max_range, &t0, &t1)) continue;
      const Position a = pts[k] + t0 * (pts[k + 1] - pts[k]);
      const Position b = pts[k] + t1 * (pts[k + 1] - pts[k]);
      const Position local[2] = {local_of(a), local_of(b)};
      if (local[0].norm() < 1e-9 || local[1].norm() < 1e-9) continue;
      const Interval iv = IntervalOf(local, 2);
      if (!in_fov(iv)) continue;
      rail_pieces.push_back({static_cast<int>(li), a, b, segment_index});
      Occluder o;
      o.owner = -1 - segment_index;
      o.is_box = false;
      o.min_distance = PointSegmentDistance(s, a, b);
      o.center_dir = UnitVector(iv.center);
      o.cos_half_width = std::cos(iv.half_width);
      o.a = a;
      o.b = b;
      occluders.push_back(o);
    }
  }

  // Azimuth bins over the field of view listing the occluders whose interval overlaps them.
  std::vector<std::vector<int>> bins;
  const double bin_width = p.fov / kAzimuthBins;
  if (options_.occlusion) {
    bins.resize(kAzimuthBins);
    for (std::size_t k = 0; k < occluders.size(); ++k) {
      const Occluder& o = occluders[k];
      const double c = std::atan2(o.center_dir.y(), o.center_dir.x());
      const double hw = std::acos(std::clamp(o.cos_half_width, -1.0, 1.0));
      // The interval may wrap through +-pi; try it shifted by a turn either way (it is narrower
      // than a half turn, so no bin is listed twice). One bin of slack on each side.
      for (const double shift : {-2.0 * kPi, 0.0, 2.0 * kPi}) {
        const int first = static_cast<int>(std::floor((c + shift - hw + half_fov) / bin_width)) - 1;
        const int last = static_cast<int>(std::floor((c + shift + hw + half_fov) / bin_width)) + 1;
        for (int bi = std::max(first, 0); bi <= std::min(last, kAzimuthBins - 1); ++bi)
          bins[bi].push_back(static_cast<int>(k));
      }
    }
  }
  // The ego's own body: checked for every scatterer (the sensors sit on it, so its angular
  // interval spans up to a half turn and does not fit the azimuth bins).
  Occluder body;
  const bool has_body =
      options_.occlusion && ego.length > 2.0 * kEgoBodySkin && ego.width > 2.0 * kEgoBodySkin;
  body.a = ego.pose.position;
  body.axis = UnitVector(ego.pose.yaw);
  body.half_length = 0.5 * ego.length - kEgoBodySkin;
  body.half_width = 0.5 * ego.width - kEgoBodySkin;
  const auto occluded = [&](const Position& q, int owner, const Polar& truth) {
    if (!options_.occlusion) return false;
    if (has_body && LengthInsideBox(body, s, q) > kEgoBodyMargin) return true;
    const Vector2 dir_local = local_of(q) / truth.range;
    const Position end = q - kOcclusionShrink * (q - s) / truth.range;
    const int bi =
        std::clamp(static_cast<int>((truth.azimuth + half_fov) / bin_width), 0, kAzimuthBins - 1);
    for (const int k : bins[bi]) {
      const Occluder& o = occluders[k];
      if (o.owner == owner || o.min_distance >= truth.range) continue;
      if (dir_local.dot(o.center_dir) < o.cos_half_width - 1e-12) continue;
      if (o.is_box ? SegmentHitsBox(o, s, end) : SegmentsIntersect(s, end, o.a, o.b)) return true;
    }
    return false;
  };

  std::vector<Scatterer> out;
  const auto consider = [&](const Position& q, const Velocity& v, double rcs_m2, int source_id,
                            int owner) {
    const Position local = local_of(q);
    Scatterer sc;
    sc.truth.range = local.norm();
    if (sc.truth.range < p.min_range || sc.truth.range > p.max_range) return;
    sc.truth.azimuth = std::atan2(local.y(), local.x());
    if (std::abs(sc.truth.azimuth) > half_fov) return;
    sc.truth.range_rate = (v - vs).dot(q - s) / sc.truth.range;
    if (!model.InWindow(sc.truth) || occluded(q, owner, sc.truth)) return;
    sc.position = q;
    sc.velocity = v;
    sc.rcs_m2 = rcs_m2;
    sc.source_id = source_id;
    out.push_back(sc);
  };

  // 2. Boxes: samples on the faces facing the sensor plus their corners, sharing the RCS.
  struct Sample {
    Position q;
    double weight;
  };
  std::vector<Sample> samples;
  for (const int ti : candidate_targets) {
    const Target& t = scene.targets[ti];
    const std::array<Position, 4> c = t.box.Corners();  // counter-clockwise
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
      WalkEdge(a, b, s, p.range_resolution, p.azimuth_resolution,
               [&](const Position& q, double ds, double sin_phi) {
                 // Share ~ projected width across the line of sight.
                 samples.push_back({q, ds * sin_phi});
                 edge_weight += ds * sin_phi;
               });
    }
    const int n_corners = static_cast<int>(std::count(corner_visible, corner_visible + 4, true));
    if (n_corners == 0) continue;
    const double rcs = std::pow(10.0, 0.1 * t.rcs_dbsm);
    const double corner_share = edge_weight > 0.0 ? kCornerShare : 1.0;
    for (int k = 0; k < 4; ++k) {
      if (!corner_visible[k]) continue;
      consider(c[k], RigidPointVelocity(t.velocity, t.yaw_rate, t.box.center, c[k]),
               rcs * corner_share / n_corners, t.id, ti);
    }
    if (edge_weight > 0.0) {
      for (const Sample& smp : samples)
        consider(smp.q, RigidPointVelocity(t.velocity, t.yaw_rate, t.box.center, smp.q),
                 rcs * (1.0 - kCornerShare) * smp.weight / edge_weight, t.id, ti);
    }
  }

  // 3. Guard rails: static line scatterers, RCS per metre of length.
  for (const RailPiece& piece : rail_pieces) {
    const Polyline& line = scene.polylines[piece.polyline];
    const double rcs_per_m = std::pow(10.0, 0.1 * line.rcs_dbsm_per_metre);
    WalkEdge(piece.a, piece.b, s, p.range_resolution, p.azimuth_resolution,
             [&](const Position& q, double ds, double) {
               consider(q, Velocity::Zero(), rcs_per_m * ds, line.id, -1 - piece.segment);
             });
  }
  return out;
}

std::vector<Detection> RadarModel::ScanSensor(int sensor, const EgoMotion& ego, const Scene& scene,
                                              std::uint64_t step) const {
  const std::vector<Scatterer> scatterers = VisibleScatterers(sensor, ego, scene);
  const SensorParams& p = params_[sensor];
  const SensorModel& model = models_[sensor];
  const Pose2 pose = SensorWorldPose(p, ego.pose);
  const Velocity vs =
      RigidPointVelocity(ego.velocity, ego.yaw_rate, ego.pose.position, pose.position);

  const auto make_detection = [&](const Polar& m, double snr_db, int source, bool clutter) {
    Detection d;
    d.sensor = sensor;
    d.range = m.range;
    d.azimuth = m.azimuth;
    d.range_rate = m.range_rate;
    d.snr_db = snr_db;
    const Position in_sensor = m.range * UnitVector(m.azimuth);
    d.position_ego = p.mount.ToParent(in_sensor);
    d.position_world = pose.ToParent(in_sensor);
    // Compensation as a real stack does it: add back the sensor's own motion along the
    // measured line of sight.
    const Vector2 los = UnitVector(pose.yaw + m.azimuth);
    d.radial_speed_compensated = m.range_rate + vs.dot(los);
    d.radial_velocity_world = d.radial_speed_compensated * los;
    d.sensor_position_world = pose.position;
    d.source_id = source;
    d.is_clutter = clutter;
    return d;
  };

  // Resolution cells: range, azimuth and range-rate bins packed into one key.
  std::vector<std::uint64_t> keys(scatterers.size());
  for (std::size_t i = 0; i < scatterers.size(); ++i) {
    const Polar& t = scatterers[i].truth;
    const auto bin = [](double v, double res) {
      return static_cast<std::uint64_t>(std::max(0.0, std::floor(v / res)));
    };
    keys[i] = (bin(t.range, p.range_resolution) << (2 * kCellBits)) |
              (model.AzimuthCell(t.azimuth) << kCellBits) |
              bin(t.range_rate - p.min_range_rate, p.range_rate_resolution);
  }
  std::vector<std::size_t> order(scatterers.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return keys[a] < keys[b]; });

  std::vector<Detection> out;
  std::uint32_t cell = 0;
  for (std::size_t begin = 0; begin < order.size(); ++cell) {
    std::size_t end = begin;
    double snr = 0.0, best = -1.0, rr = 0.0;
    Position centroid = Position::Zero();
    int source = -1;
    for (; end < order.size() && keys[order[end]] == keys[order[begin]]; ++end) {
      const Scatterer& sc = scatterers[order[end]];
      const double si = model.SnrLinear(sc.rcs_m2, sc.truth.range);
      snr += si;
      centroid += si * sc.position;
      rr += si * sc.truth.range_rate;
      if (si > best) {
        best = si;
        source = sc.source_id;
      }
    }
    begin = end;
    if (!(snr > 0.0)) continue;
    centroid /= snr;
    const Position local = pose.ToLocal(centroid);
    const Polar truth{local.norm(), std::atan2(local.y(), local.x()), rr / snr};
    assert(cell < (1u << kCellBits));
    CounterRng rng(seed_, RngPurpose::kRadarScatter, step,
                   (static_cast<std::uint32_t>(sensor) << kCellBits) | cell);
    const std::optional<Polar> m = model.Measure(truth, snr, options_.noise, rng);
    if (m) out.push_back(make_detection(*m, 10.0 * std::log10(snr), source, false));
  }

  if (options_.false_alarms) {
    CounterRng rng(seed_, RngPurpose::kRadarClutter, step, static_cast<std::uint32_t>(sensor));
    const std::uint32_t n = rng.Poisson(model.ExpectedFalseAlarms());
    for (std::uint32_t k = 0; k < n; ++k) {
      Polar m;
      m.range = rng.Uniform(p.min_range, p.max_range);
      // Uniform over the azimuth cells (each cell has the same false-alarm probability), not
      // over the angle: rejection with the acceptance azimuth_resolution / resolution(az) >= 1 %
      // (profile factors <= 100), so wide off-boresight cells get no more than their share.
      do {
        m.azimuth = rng.Uniform(-0.5 * p.fov, 0.5 * p.fov);
      } while (rng.Uniform() * p.AzimuthResolutionAt(m.azimuth) > p.azimuth_resolution);
      m.range_rate = rng.Uniform(p.min_range_rate, p.max_range_rate);
      out.push_back(make_detection(m, model.ThresholdSnrDb(), -1, true));
    }
  }
  return out;
}

std::vector<Detection> RadarModel::Scan(const EgoMotion& ego, const Scene& scene,
                                        std::uint64_t step, double time, double step_length) const {
  const std::vector<int> due = SensorsDue(time, step_length);
  std::vector<std::vector<Detection>> per_sensor(due.size());
  // Sensors are independent and their random streams are addressed by sensor, so the
  // result does not depend on the schedule.
#pragma omp parallel for schedule(dynamic, 1)
  for (int i = 0; i < static_cast<int>(due.size()); ++i)
    per_sensor[i] = ScanSensor(due[i], ego, scene, step);
  std::vector<Detection> out;
  for (auto& v : per_sensor) out.insert(out.end(), v.begin(), v.end());
  return out;
}

}  // namespace dualgrid::radar
