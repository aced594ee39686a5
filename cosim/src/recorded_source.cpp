#include "dualgrid/cosim/recorded_source.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "dualgrid/cosim/pipeline.hpp"

namespace dualgrid::cosim {

namespace {

constexpr const char* kLabelNames[] = {"car",
                                       "large_vehicle",
                                       "truck",
                                       "bus",
                                       "train",
                                       "bicycle",
                                       "motorised_two_wheeler",
                                       "pedestrian",
                                       "pedestrian_group",
                                       "animal",
                                       "other",
                                       "static"};

// A track's velocity over ground [m/s] from its points (docs/recorded-data.md, "Track
// velocity"): the least-squares fit of v . u_i = v_r,i over the points' lines of sight when they
// span enough directions; else the slope of the per-scan centroids over time; else the mean
// Doppler along the mean line of sight (the radial part only).
struct TrackSample {
  double t;  // [s] relative to the step
  Position p;
  Vector2 u;
  double vr;
};

Velocity TrackVelocity(const std::vector<TrackSample>& s) {
  Matrix2 a = Matrix2::Zero();
  Vector2 b = Vector2::Zero();
  for (const TrackSample& x : s) {
    a += x.u * x.u.transpose();
    b += x.vr * x.u;
  }
  const double n = static_cast<double>(s.size());
  const double det_a = a(0, 0) * a(1, 1) - a(0, 1) * a(1, 0);
  // Smallest eigenvalue of the mean u u^T: sin^2 of the lines of sight's spread, roughly. 0.02
  // is a spread of about 8 degrees, where a 0.1 m/s Doppler error becomes ~0.7 m/s across.
  const double tr = a.trace() / n, det = det_a / (n * n);
  const double lambda_min = 0.5 * tr - std::sqrt(std::max(0.0, 0.25 * tr * tr - det));
  if (s.size() >= 2 && lambda_min >= 0.02) {  // A v = b, 2 x 2 (A symmetric, det > 0 here)
    return Vector2(a(1, 1) * b.x() - a(0, 1) * b.y(), a(0, 0) * b.y() - a(1, 0) * b.x()) / det_a;
  }
  // Centroids per distinct time.
  std::vector<std::pair<double, Position>> c;
  for (const TrackSample& x : s) {
    if (c.empty() || c.back().first != x.t) c.push_back({x.t, Position::Zero()});
  }
  if (c.size() >= 3 && c.back().first - c.front().first >= 0.1) {
    for (auto& [t, p] : c) {
      int k = 0;
      for (const TrackSample& x : s)
        if (x.t == t) p += x.p, ++k;
      p /= k;
    }
    double mt = 0.0;
    Position mp = Position::Zero();
    for (const auto& [t, p] : c) mt += t, mp += p;
    mt /= c.size();
    mp /= static_cast<double>(c.size());
    double stt = 0.0;
    Vector2 stp = Vector2::Zero();
    for (const auto& [t, p] : c) stt += (t - mt) * (t - mt), stp += (t - mt) * (p - mp);
    return stp / stt;
  }
  Vector2 u = Vector2::Zero();
  double vr = 0.0;
  for (const TrackSample& x : s) u += x.u, vr += x.vr;
  return u.norm() > 0.0 ? Vector2((vr / n) * u.normalized()) : Vector2::Zero();
}

}  // namespace

RecordedSource::RecordedSource(const RecordedSequence& sequence, RecordedOptions options)
    : seq_(sequence), options_(options), radar_(sequence.sensors, {}, 0) {
  if (!(options_.batch_window >= 0.0) || !(options_.track_window >= 0.0) ||
      !(options_.first_dt > 0.0))
    throw std::invalid_argument("RecordedOptions: windows must be >= 0 and first_dt > 0");
  const std::int64_t window_us = std::llround(options_.batch_window * 1e6);
  for (std::size_t i = 0; i < seq_.scans.size(); ++i)
    if (batches_.empty() ||
        seq_.scans[i].timestamp_us - seq_.scans[batches_.back()].timestamp_us > window_us)
      batches_.push_back(i);
  batches_.push_back(seq_.scans.size());
  point_time_.resize(seq_.points.size());
  point_los_.resize(seq_.points.size());
  track_points_.resize(seq_.track_names.size());
  for (const RecordedScan& s : seq_.scans) {
    const Pose2 sensor = radar_.SensorPose(s.sensor, s.ego_pose);
    for (std::size_t i = s.begin; i < s.end; ++i) {
      point_time_[i] = s.timestamp_us;
      point_los_[i] = UnitVector(sensor.yaw + seq_.points[i].azimuth);
      const int track = seq_.points[i].track;
      if (track >= 0 && IsMovingLabel(seq_.points[i].label)) track_points_[track].push_back(i);
    }
  }
  // Scans are in time order, so each track's points are too.
  first_dt_ = options_.first_dt;
}

std::unique_ptr<DetectionSource> RecordedSource::Twin() const {
  auto twin = std::make_unique<RecordedSource>(seq_, options_);
  twin->Start();
  return twin;
}

double RecordedSource::first_time() const {
  return seq_.scans.empty() ? 0.0 : seq_.Time(seq_.scans.front().timestamp_us);
}

double RecordedSource::last_time() const {
  return seq_.scans.empty() ? 0.0
                            : seq_.Time(seq_.scans[batches_[batches_.size() - 2]].timestamp_us);
}

bool RecordedSource::Advance(IdRegistry& ids) {
  if (advanced_) ++batch_;
  if (batch_ + 1 >= batches_.size()) return false;
  advanced_ = true;
  const RecordedScan& first = seq_.scans[batches_[batch_]];
  next_ = batches_[batch_ + 1];
  frame_.step = static_cast<int>(batch_) + 1;  // as `run`: the first step is 1
  frame_.time = seq_.Time(first.timestamp_us);
  sim::VehicleState& e = frame_.ego;
  e.id = "ego";
  e.type = "ego";
  e.box = {first.ego_pose.position, first.ego_pose.yaw, seq_.ego_length, seq_.ego_width};
  e.velocity = first.ego_velocity;
  e.yaw_rate = first.ego_yaw_rate;
  e.speed = first.ego_velocity.norm();
  e.lane_yaw = first.lane_yaw;
  ego_ = {first.ego_pose, first.ego_velocity, first.ego_yaw_rate, seq_.ego_length, seq_.ego_width};
  if (seq_.annotated) {
    // The references are sorted by id per scan (the reader's contract).
    frame_.vehicles.clear();
    for (std::size_t k = first.ref_begin; k < first.ref_end; ++k) {
      const recorded::ReferenceObject& r = seq_.references[k];
      sim::VehicleState v;
      v.id = r.id;
      v.type = r.type;
      v.box = r.box;
      v.velocity = r.velocity;
      v.speed = r.velocity.norm();
      v.lane_yaw = r.box.yaw;
      ids.Id(v.id);
      frame_.vehicles.push_back(std::move(v));
    }
  } else {
    EstimateTracks(ids);
  }
  return true;
}

void RecordedSource::EstimateTracks(IdRegistry& ids) {
  frame_.vehicles.clear();
  const std::int64_t now = seq_.scans[batches_[batch_]].timestamp_us;
  const std::int64_t half = std::llround(options_.track_window * 1e6);
  std::vector<TrackSample> samples;
  for (std::size_t k = 0; k < track_points_.size(); ++k) {
    const std::vector<std::size_t>& pts = track_points_[k];
    const auto lo =
        std::lower_bound(pts.begin(), pts.end(), now - half,
                         [&](std::size_t i, std::int64_t t) { return point_time_[i] < t; });
    samples.clear();
    double rcs = 0.0;
    for (auto it = lo; it != pts.end() && point_time_[*it] <= now + half; ++it) {
      const RecordedPoint& p = seq_.points[*it];
      samples.push_back({static_cast<double>(point_time_[*it] - now) / 1e6, p.position,
                         point_los_[*it], p.radial_speed});
      rcs += p.rcs;
    }
    if (samples.empty()) continue;
    const Velocity v = TrackVelocity(samples);
    // The points moved to the step's time, then their extent along and across the motion.
    const double yaw = v.norm() > 0.5 ? std::atan2(v.y(), v.x()) : 0.0;
    const Pose2 axes{Position::Zero(), yaw};
    Vector2 lo_e = Vector2::Constant(1e300), hi_e = Vector2::Constant(-1e300);
    for (const TrackSample& x : samples) {
      const Vector2 q = axes.RotateToLocal(x.p - x.t * v);
      lo_e = lo_e.cwiseMin(q);
      hi_e = hi_e.cwiseMax(q);
    }
    sim::VehicleState o;
    o.id = seq_.track_names[k];
    o.type = kLabelNames[seq_.points[pts.front()].label];
    const Vector2 extent = (hi_e - lo_e).cwiseMax(Vector2::Constant(1.0));
    o.box = {axes.RotateToParent(0.5 * (lo_e + hi_e)), yaw, extent.x(), extent.y()};
    o.velocity = v;
    o.speed = v.norm();
    o.lane_yaw = yaw;
    o.rcs_dbsm = rcs / static_cast<double>(samples.size());
    frame_.vehicles.push_back(std::move(o));
  }
  std::sort(frame_.vehicles.begin(), frame_.vehicles.end(),
            [](const auto& a, const auto& b) { return a.id < b.id; });
  for (const sim::VehicleState& v : frame_.vehicles) ids.Id(v.id);
}

void RecordedSource::Scan(IdRegistry& ids, std::vector<radar::Detection>* detections,
                          std::vector<int>* scanned) {
  detections->clear();
  scanned->clear();
  labels_.clear();
  for (std::size_t k = batches_[batch_]; k < batches_[batch_ + 1]; ++k) {
    const RecordedScan& s = seq_.scans[k];
    // Each scan's sensor where the ego was at its own timestamp.
    const Pose2 pose = radar_.SensorPose(s.sensor, s.ego_pose);
    if (std::find(scanned->begin(), scanned->end(), s.sensor) == scanned->end())
      scanned->push_back(s.sensor);
    for (std::size_t i = s.begin; i < s.end; ++i) {
      const RecordedPoint& p = seq_.points[i];
      radar::Detection d;
      d.sensor = s.sensor;
      d.range = p.range;
      d.azimuth = p.azimuth;
      d.range_rate = p.range_rate;
      d.snr_db = p.rcs;  // no SNR in the data: the RCS stands in (figures only)
      d.position_world = p.position;
      d.position_ego = s.ego_pose.ToLocal(p.position);
      // The radar model's compensation formula, so that a simulated run's export reproduces it.
      const Vector2 los = UnitVector(pose.yaw + p.azimuth);
      d.radial_speed_compensated = p.radial_speed;
      d.radial_velocity_world = p.radial_speed * los;
      d.sensor_position_world = pose.position;
      d.source_id = p.track >= 0 ? ids.Id(seq_.track_names[p.track]) : -1;
      detections->push_back(d);
      labels_.push_back(p.label);
    }
  }
}

scenario::ScenarioConfig DefaultRecordedConfig() {
  scenario::ScenarioConfig c;
  c.filter.length_x = 100.0;
  c.filter.width_y = 60.0;
  return c;
}

RecordedOptions FitConfig(const RecordedSequence& seq, double batch_window,
                          scenario::ScenarioConfig* config) {
  RecordedOptions o;
  o.batch_window = batch_window;
  o.first_dt = config->filter.cycle;
  const RecordedSource probe(seq, o);
  config->sim.name = seq.name;
  config->sim.duration = probe.last_time();
  config->sim.step_length = probe.last_time() / probe.StepCount();
  if (!(config->sim.step_length > 0.0))
    throw std::invalid_argument(seq.name + ": the scans span no time (the last at t = 0)");
  config->radar.sensors.clear();  // the sequence's radars
  return o;
}

}  // namespace dualgrid::cosim
