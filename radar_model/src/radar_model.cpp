#include "dualgrid/radar_model/radar_model.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <utility>

#include "edge_walk.hpp"
#include "ghosts.hpp"
#include "scan_geometry.hpp"

namespace dualgrid::radar {
namespace {

using namespace detail;  // NOLINT: the scan's own geometry helpers

constexpr int kCellBits = 20;         // per packed cell-index dimension and per RNG index
constexpr int kMaxSensors = 1 << 12;  // sensor << kCellBits must fit the 32-bit RNG index
struct SensorGeometry {
  Pose2 pose;
  Velocity velocity;  // over ground, including the yaw-rate lever arm
};

struct RailPiece {
  int polyline;
  Position a, b;
  int segment;
  double rcs_per_m;  // [m^2 / m]
};

// One thread's working memory for the scans of one sensor at a time, kept between calls so that
// a scan allocates nothing once warmed up (a step's sensors run on several threads, each with
// its own). Every user clears what it takes.
struct ScanScratch {
  std::vector<Occluder> occluders;
  std::vector<int> candidate_targets;
  std::vector<std::array<Position, 4>> candidate_corners;  // the candidates' box corners
  std::vector<RailPiece> rail_pieces;
  std::vector<Edge> rail_edges;        // the pieces' ends, for WalkEdges
  std::vector<int> piece_of;           // the rail piece of each kept rail scatterer
  std::vector<int> piece_starts;       // GroupByPiece's counts
  std::vector<Scatterer> rail_buffer;  // GroupByPiece's copy
  std::vector<std::vector<int>> bins;  // kAzimuthBins lists when occlusion is on
  std::vector<FaceSample> samples;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> cells;  // (resolution cell, scatterer)
};

ScanScratch& Scratch() {
  thread_local ScanScratch scratch;
  return scratch;
}

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

// Step 3 of VisibleScatterers for the pieces in scratch.rail_pieces: walked together
// (WalkEdge's samples, several pieces on SIMD lanes, those outside the cone's range or field of
// view dropped there), each kept sample handed to consider_kept(q, local, range, velocity, rcs,
// source id, owner) -> bool (a scatterer appended to *out) as it comes, then the new scatterers
// put back piece after piece: the order of walking the pieces one by one.
template <class ConsiderKept>
void ScanRails(const Scene& scene, const SensorCone& cone, const SensorParams& p,
               ConsiderKept& consider_kept, std::vector<Scatterer>* out, ScanScratch& scratch) {
  const std::vector<RailPiece>& pieces = scratch.rail_pieces;
  std::vector<Edge>& edges = scratch.rail_edges;
  edges.clear();
  for (const RailPiece& piece : pieces) edges.push_back({piece.a, piece.b});
  const std::size_t begin = out->size();
  std::vector<int>& piece_of = scratch.piece_of;
  piece_of.clear();
  auto sink = [&](int k, const EdgeSample& e) {
    const RailPiece& piece = pieces[k];
    if (consider_kept(e.q, e.local, e.range, Velocity::Zero(), piece.rcs_per_m * e.ds,
                      scene.polylines[piece.polyline].id, -1 - piece.segment))
      piece_of.push_back(k);
  };
  WalkEdges(edges.data(), static_cast<int>(edges.size()), cone, p.range_resolution,
            p.azimuth_resolution, sink);
  GroupByPiece(out, begin, piece_of, static_cast<int>(pieces.size()), scratch);
}

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
  std::string error;
  if (!options_.multipath.IsValid(&error))
    throw std::invalid_argument("radar options: multipath." + error);
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
  ScanScratch& scratch = Scratch();
  std::vector<Occluder>& occluders = scratch.occluders;
  std::vector<int>& candidate_targets = scratch.candidate_targets;
  occluders.clear();
  candidate_targets.clear();
  scratch.candidate_corners.clear();
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
    scratch.candidate_corners.push_back(corners);
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
  std::vector<RailPiece>& rail_pieces = scratch.rail_pieces;
  rail_pieces.clear();
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
      rail_pieces.push_back({static_cast<int>(li), a, b, segment_index,
                             std::pow(10.0, 0.1 * scene.polylines[li].rcs_dbsm_per_metre)});
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
  std::vector<std::vector<int>>& bins = scratch.bins;
  const double bin_width = p.fov / kAzimuthBins;
  if (options_.occlusion) {
    bins.resize(kAzimuthBins);
    for (std::vector<int>& bin : bins) bin.clear();
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
  // The ego's body hides q (needs no azimuth).
  const auto behind_body = [&](const Position& q) {
    return has_body && LengthInsideBox(body, s, q) > kEgoBodyMargin;
  };
  // Another occluder hides q (the azimuth bins'); with behind_body, occluded(q, owner, truth).
  const auto behind_others = [&](const Position& q, int owner, const Polar& truth) {
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
  const auto occluded = [&](const Position& q, int owner, const Polar& truth) {
    return options_.occlusion && (behind_body(q) || behind_others(q, owner, truth));
  };

  std::vector<Scatterer> out;
  // Most walked rail samples lie outside the field of view (a rail piece is walked whole once
  // some of it is in view): those that OutsideFov rejects skip the atan2 (the same outcome).
  const double fov_cos_bound = FovCosBound(half_fov);
  // A point q kept by the first tests (range and field of view), with its local coordinates and
  // range: the azimuth, the window and occlusion decide. True when it became a scatterer. The
  // tests are pure and all must pass, so their order does not change the outcome: the ego's body
  // first (it needs no azimuth, and a corner radar's view along the car is mostly behind it),
  // then the atan2 and the rest.
  const auto consider_kept = [&](const Position& q, const Position& local, double range,
                                 const Velocity& v, double rcs_m2, int source_id, int owner) {
    if (behind_body(q)) return false;
    Scatterer sc;
    sc.truth.range = range;
    sc.truth.azimuth = std::atan2(local.y(), local.x());
    if (std::abs(sc.truth.azimuth) > half_fov) return false;
    sc.truth.range_rate = (v - vs).dot(q - s) / sc.truth.range;
    if (!model.InWindow(sc.truth) || (options_.occlusion && behind_others(q, owner, sc.truth)))
      return false;
    sc.position = q;
    sc.velocity = v;
    sc.rcs_m2 = rcs_m2;
    sc.source_id = source_id;
    sc.origin = q;
    out.push_back(sc);
    return true;
  };
  const auto consider = [&](const Position& q, const Velocity& v, double rcs_m2, int source_id,
                            int owner) {
    const Position local = local_of(q);
    const double range = local.norm();
    if (range < p.min_range || range > p.max_range) return;
    if (OutsideFov(local, range, fov_cos_bound)) return;
    consider_kept(q, local, range, v, rcs_m2, source_id, owner);
  };

  // 2. Boxes: samples on the faces facing the sensor plus their corners, sharing the RCS.
  std::vector<FaceSample>& samples = scratch.samples;
  for (std::size_t c = 0; c < candidate_targets.size(); ++c) {
    const int ti = candidate_targets[c];
    const Target& t = scene.targets[ti];
    BoxScatterers(scratch.candidate_corners[c], std::pow(10.0, 0.1 * t.rcs_dbsm), s,
                  p.range_resolution, p.azimuth_resolution, samples,
                  [&](const Position& q, double rcs_share) {
                    consider(q, RigidPointVelocity(t.velocity, t.yaw_rate, t.box.center, q),
                             rcs_share, t.id, ti);
                  });
  }

  // 3. Guard rails: static line scatterers, RCS per metre of length.
  SensorCone cone;
  cone.position = s;
  cone.to_local = to_local;
  cone.min_range = p.min_range;
  cone.max_range = p.max_range;
  cone.fov_cos_bound = fov_cos_bound;
  ScanRails(scene, cone, p, consider_kept, &out, scratch);

  // 4. Multipath: the boxes' ghosts in the mirrors (docs/radar.md, "Multipath").
  if (options_.multipath.enabled) {
    SensorView view;
    view.params = &p;
    view.model = &model;
    view.s = s;
    view.vs = vs;
    view.to_local = to_local;
    view.cos_half_fov = std::cos(half_fov);
    view.occlusion = options_.occlusion;
    view.has_body = has_body;
    view.body = body;
    if (has_body)
      for (const Position& c :
           OrientedBox{ego.pose.position, ego.pose.yaw, ego.length, ego.width}.Corners())
        view.body_box.Add(c);
    AddGhostScatterers(view, options_.multipath, scene, occluded, &out);
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
  // Pose2's ToParent / ToLocal with their rotations made once (the same products).
  const Matrix2 mount_rotation = Rotation(p.mount.yaw), pose_rotation = Rotation(pose.yaw);
  const Matrix2 to_local = pose_rotation.transpose();

  const auto make_detection = [&](const Polar& m, double snr_db, int source, bool clutter) {
    Detection d;
    d.sensor = sensor;
    d.range = m.range;
    d.azimuth = m.azimuth;
    d.range_rate = m.range_rate;
    d.snr_db = snr_db;
    const Position in_sensor = m.range * UnitVector(m.azimuth);
    d.position_ego = p.mount.position + mount_rotation * in_sensor;
    d.position_world = pose.position + pose_rotation * in_sensor;
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

  // Resolution cells: range, azimuth and range-rate bins packed into one key, sorted with the
  // scatterers' indices as the tie-break (the order of a stable sort by key, without its buffer).
  std::vector<std::pair<std::uint64_t, std::uint32_t>>& cells = Scratch().cells;
  assert(scatterers.size() <= UINT32_MAX);
  cells.resize(scatterers.size());
  for (std::size_t i = 0; i < scatterers.size(); ++i) {
    const Polar& t = scatterers[i].truth;
    const auto bin = [](double v, double res) {
      return static_cast<std::uint64_t>(std::max(0.0, std::floor(v / res)));
    };
    cells[i] = {(bin(t.range, p.range_resolution) << (2 * kCellBits)) |
                    (model.AzimuthCell(t.azimuth) << kCellBits) |
                    bin(t.range_rate - p.min_range_rate, p.range_rate_resolution),
                static_cast<std::uint32_t>(i)};
  }
  std::sort(cells.begin(), cells.end());

  std::vector<Detection> out;
  // Random streams per cell: cells holding a direct scatterer are numbered among themselves (so
  // with multipath off nothing changes, and on, a cell without ghosts draws what it drew
  // without them); cells of ghosts alone have their own purpose and numbering.
  std::uint32_t cell = 0, ghost_cell = 0;
  for (std::size_t begin = 0; begin < cells.size();) {
    std::size_t end = begin;
    double snr = 0.0, best = -1.0, rr = 0.0;
    Position centroid = Position::Zero();
    const Scatterer* strongest = nullptr;
    bool has_direct = false;
    for (; end < cells.size() && cells[end].first == cells[begin].first; ++end) {
      const Scatterer& sc = scatterers[cells[end].second];
      const double si = model.SnrLinear(sc.rcs_m2, sc.truth.range);
      snr += si;
      centroid += si * sc.position;
      rr += si * sc.truth.range_rate;
      has_direct = has_direct || sc.path == Path::kDirect;
      if (si > best) {
        best = si;
        strongest = &sc;
      }
    }
    begin = end;
    const std::uint32_t ordinal = has_direct ? cell++ : ghost_cell++;
    if (!(snr > 0.0)) continue;
    centroid /= snr;
    const Position local = to_local * (centroid - pose.position);
    const Polar truth{local.norm(), std::atan2(local.y(), local.x()), rr / snr};
    assert(ordinal < (1u << kCellBits));
    CounterRng rng(seed_, has_direct ? RngPurpose::kRadarScatter : RngPurpose::kRadarGhost, step,
                   (static_cast<std::uint32_t>(sensor) << kCellBits) | ordinal);
    const std::optional<Polar> m = model.Measure(truth, snr, options_.noise, rng);
    if (!m) continue;
    const bool ghost = strongest->path != Path::kDirect;
    Detection d =
        make_detection(*m, 10.0 * std::log10(snr), ghost ? -1 : strongest->source_id, false);
    if (ghost) {
      d.path = strongest->path;
      d.bounces = strongest->bounces;
      d.reflector_id = strongest->reflector_id;
      d.ghost_of = strongest->source_id;
    }
    out.push_back(d);
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
