#include "dualgrid/radar_model/radar_model.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <utility>

#include <omp.h>

#include "scan_geometry.hpp"
#include "sensor_scan.hpp"

namespace dualgrid::radar {
namespace {

using namespace detail;  // NOLINT: the scan's own geometry helpers

constexpr int kCellBits = 20;         // per packed cell-index dimension and per RNG index
constexpr int kMaxSensors = 1 << 12;  // sensor << kCellBits must fit the 32-bit RNG index

// The step's scans of one thread: a scratch per sensor in flight, the targets' geometry, the
// rail walk's memory; kept between steps (no allocation once warmed up).
struct StepScratch {
  std::vector<ScanScratch> sensors;
  std::vector<TargetGeometry> targets;
  RailWalkScratch rails;
  std::vector<RailWalkScratch> rail_groups;  // Scan's groups of sensors, one per thread
};

StepScratch& Scratch() {
  thread_local StepScratch scratch;
  return scratch;
}

// The false alarms of one sensor's scan, appended to *out.
template <class MakeDetection>
void AddFalseAlarms(const SensorParams& p, const SensorModel& model, CounterRng& rng,
                    const MakeDetection& make_detection, std::vector<Detection>* out) {
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
    out->push_back(make_detection(m, model.ThresholdSnrDb(), -1, true));
  }
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
  StepScratch& scratch = Scratch();
  scratch.sensors.resize(std::max<std::size_t>(scratch.sensors.size(), 1));
  ComputeTargetGeometry(scene, &scratch.targets);
  SensorScan scan(params_[sensor], models_[sensor], options_, ego, scene, scratch.targets,
                  scratch.sensors[0]);
  SensorScan* const scans[1] = {&scan};
  ScanRails(scans, scratch.rails);
  scan.AddGhosts();
  return scratch.sensors[0].scatterers;
}

std::vector<Detection> RadarModel::ScanSensor(int sensor, const EgoMotion& ego, const Scene& scene,
                                              std::uint64_t step) const {
  const std::vector<Scatterer> scatterers = VisibleScatterers(sensor, ego, scene);
  std::vector<Detection> out;
  Detect(sensor, ego, scatterers, step, &out);
  return out;
}

void RadarModel::Detect(int sensor, const EgoMotion& ego, const std::vector<Scatterer>& scatterers,
                        std::uint64_t step, std::vector<Detection>* out) const {
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
  thread_local std::vector<std::pair<std::uint64_t, std::uint32_t>> cells;
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
    out->push_back(d);
  }

  if (options_.false_alarms) {
    CounterRng rng(seed_, RngPurpose::kRadarClutter, step, static_cast<std::uint32_t>(sensor));
    AddFalseAlarms(p, model, rng, make_detection, out);
  }
}

std::vector<Detection> RadarModel::Scan(const EgoMotion& ego, const Scene& scene,
                                        std::uint64_t step, double time, double step_length) const {
  const std::vector<int> due = SensorsDue(time, step_length);
  const int n = static_cast<int>(due.size());
  StepScratch& scratch = Scratch();
  if (scratch.sensors.size() < due.size()) scratch.sensors.resize(due.size());
  ComputeTargetGeometry(scene, &scratch.targets);
  // Each sensor's steps 1 and 2, then the rails of all sensors walked together on the SIMD lanes
  // (ScanRails), then each sensor's ghosts and detections. Sensors are independent and their
  // random streams are addressed by sensor, so the result does not depend on the schedule.
  std::vector<std::optional<SensorScan>> scans(due.size());
#pragma omp parallel for schedule(dynamic, 1)
  for (int i = 0; i < n; ++i)
    scans[i].emplace(params_[due[i]], models_[due[i]], options_, ego, scene, scratch.targets,
                     scratch.sensors[i]);
  // Called outside a parallel region with threads to spare (dualgrid sim, Python), the sensors'
  // rails are walked in groups, one per thread; a sensor's samples do not depend on its group.
  const int groups = omp_in_parallel() ? 1 : std::max(1, std::min(n, omp_get_max_threads()));
  if (static_cast<int>(scratch.rail_groups.size()) < groups) scratch.rail_groups.resize(groups);
#pragma omp parallel for schedule(static, 1) if (groups > 1)
  for (int g = 0; g < groups; ++g) {
    std::vector<SensorScan*> walking;
    for (int i = g; i < n; i += groups) walking.push_back(&*scans[i]);
    ScanRails(walking, scratch.rail_groups[g]);
  }
#pragma omp parallel for schedule(dynamic, 1)
  for (int i = 0; i < n; ++i) {
    scans[i]->AddGhosts();
    scratch.sensors[i].detections.clear();
    Detect(due[i], ego, scratch.sensors[i].scatterers, step, &scratch.sensors[i].detections);
  }
  std::size_t total = 0;
  for (int i = 0; i < n; ++i) total += scratch.sensors[i].detections.size();
  std::vector<Detection> out;
  out.reserve(total);
  for (int i = 0; i < n; ++i)
    out.insert(out.end(), scratch.sensors[i].detections.begin(),
               scratch.sensors[i].detections.end());
  return out;
}

}  // namespace dualgrid::radar
