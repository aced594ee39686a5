// Geometry properties over sampled poses, noise and clutter off unless stated. Targets are
// 5 mm boxes with a 30 dBsm RCS: detected with certainty (SNR > 30 dB) and so small that all
// their scatterers lie within delta = atan(half_diagonal / (R - half_diagonal)) of the line of
// sight to the box centre; tolerances follow from that angle.
#include <catch2/catch.hpp>

#include <omp.h>
#include <cmath>
#include <vector>

#include "dualgrid/radar_model/radar_model.hpp"

using namespace dualgrid;
using namespace dualgrid::radar;

namespace {

constexpr double kTiny = 0.005;  // target box side [m]

struct Sample {
  EgoMotion ego;
  Pose2 sensor;
  Velocity sensor_velocity;
  Position target;
  Vector2 los;  // world unit vector sensor -> target centre
  double range = 0.0;
  double delta = 0.0;  // max angle between any scatterer's line of sight and los
};

Sample Draw(const SensorParams& p, std::uint64_t stream, int index, bool yaw_rate) {
  CounterRng rng(17, RngPurpose::kTest, stream, index);
  Sample s;
  const double yaw = rng.Uniform(-kPi, kPi);
  s.ego.pose = Pose2{Position(rng.Uniform(-500, 500), rng.Uniform(-500, 500)), yaw};
  s.ego.velocity = rng.Uniform(0.0, 35.0) * UnitVector(yaw);
  s.ego.yaw_rate = yaw_rate ? rng.Uniform(-0.3, 0.3) : 0.0;
  s.sensor = SensorWorldPose(p, s.ego.pose);
  s.sensor_velocity =
      RigidPointVelocity(s.ego.velocity, s.ego.yaw_rate, s.ego.pose.position, s.sensor.position);
  const double az = rng.Uniform(-0.8, 0.8) * 0.5 * p.fov;
  s.range = rng.Uniform(10.0, 0.7 * p.max_range);
  s.target = s.sensor.ToParent(s.range * UnitVector(az));
  s.los = UnitVector(s.sensor.yaw + az);
  const double hd = 0.5 * std::hypot(kTiny, kTiny);
  s.delta = std::atan(hd / (s.range - hd));
  return s;
}

Scene OneTarget(const Position& at, const Velocity& v, double box_yaw) {
  Scene scene;
  scene.targets.push_back({42, OrientedBox{at, box_yaw, kTiny, kTiny}, v, 0.0, 30.0});
  return scene;
}

const ModelOptions kExact{false, false, true, {}};

// Checks shared by all geometry cases: frames and eq. (1) velocity are consistent.
void CheckFrames(const Detection& d, const Sample& s) {
  CHECK(d.source_id == 42);
  CHECK_FALSE(d.is_clutter);
  CHECK((d.position_world - s.target).norm() < kTiny);
  CHECK((s.ego.pose.ToLocal(d.position_world) - d.position_ego).norm() < 1e-9);
  CHECK((d.sensor_position_world - s.sensor.position).norm() < 1e-12);
  const Vector2 los_meas = (d.position_world - d.sensor_position_world) / d.range;
  CHECK((d.radial_velocity_world - d.radial_speed_compensated * los_meas).norm() < 1e-9);
}

}  // namespace

TEST_CASE("Compensated radial speed: full speed along the line of sight, ~0 across it",
          "[radar][geometry][property]") {
  const std::vector<SensorParams> rig = DefaultRig(4.5, 1.8);
  const int sensor = GENERATE(range(0, 5));
  const int index = GENERATE(range(0, 40));
  const RadarModel model(rig, kExact, 1);
  const Sample s = Draw(rig[sensor], 1, index, true);
  CounterRng rng(18, RngPurpose::kTest, sensor, index);
  const double vt = rng.Uniform(-25.0, 15.0);  // keeps range rate inside both windows
  // comp - expected = vt (u_i.u - 1) + (v_target - v_sensor).(mean u_i - centroid dir):
  // bounded by (|vt| + |v_sensor|) 2 sin(delta).
  const double tol = (std::abs(vt) + s.sensor_velocity.norm()) * 2.0 * std::sin(s.delta) + 1e-9;
  const Vector2 across(-s.los.y(), s.los.x());
  for (const bool along : {true, false}) {
    const Velocity v = vt * (along ? s.los : across);
    const std::vector<Detection> dets =
        model.ScanSensor(sensor, s.ego, OneTarget(s.target, v, rng.Uniform(-kPi, kPi)), index);
    REQUIRE_FALSE(dets.empty());
    for (const Detection& d : dets) {
      CheckFrames(d, s);
      CHECK(std::abs(d.radial_speed_compensated - (along ? vt : 0.0)) <= tol);
      // The measured range rate is relative to the moving sensor.
      CHECK(std::abs(d.range_rate - (v - s.sensor_velocity).dot(s.los)) <=
            (v - s.sensor_velocity).norm() * 2.0 * std::sin(s.delta) + 1e-9);
    }
  }
}

TEST_CASE("Static obstacle: zero compensated, -v cos(azimuth) uncompensated",
          "[radar][geometry][property]") {
  const std::vector<SensorParams> rig = DefaultRig(4.5, 1.8);
  const int sensor = GENERATE(range(0, 5));
  const int index = GENERATE(range(0, 40));
  const RadarModel model(rig, kExact, 1);
  const Sample s = Draw(rig[sensor], 2, index, false);
  const double speed = s.ego.velocity.norm();
  const double tol = speed * 2.0 * std::sin(s.delta) + 1e-9;
  const std::vector<Detection> dets =
      model.ScanSensor(sensor, s.ego, OneTarget(s.target, Velocity::Zero(), 0.3), index);
  REQUIRE_FALSE(dets.empty());
  for (const Detection& d : dets) {
    CheckFrames(d, s);
    CHECK(std::abs(d.radial_speed_compensated) <= tol);
    // Azimuth relative to the direction of travel = mount yaw + sensor azimuth.
    CHECK(std::abs(d.range_rate + speed * std::cos(rig[sensor].mount.yaw + d.azimuth)) <= tol);
  }
}

TEST_CASE("Yaw-rate lever arm enters the sensor velocity", "[radar][geometry][property]") {
  const std::vector<SensorParams> rig = DefaultRig(4.5, 1.8);
  const int sensor = GENERATE(range(0, 5));
  const int index = GENERATE(range(0, 40));
  const RadarModel model(rig, kExact, 1);
  Sample s = Draw(rig[sensor], 3, index, true);
  const double omega = s.ego.yaw_rate;
  // Sensor velocity by hand: ego centre velocity plus omega x lever arm (world frame).
  const Vector2 arm = s.sensor.position - s.ego.pose.position;
  const Velocity vs = s.ego.velocity + omega * Vector2(-arm.y(), arm.x());
  const double tol = vs.norm() * 2.0 * std::sin(s.delta) + 1e-9;
  const std::vector<Detection> dets =
      model.ScanSensor(sensor, s.ego, OneTarget(s.target, Velocity::Zero(), 0.0), index);
  REQUIRE_FALSE(dets.empty());
  for (const Detection& d : dets) {
    CheckFrames(d, s);
    const Vector2 los = UnitVector(s.sensor.yaw + d.azimuth);
    CHECK(std::abs(d.range_rate + vs.dot(los)) <= tol);
    CHECK(std::abs(d.radial_speed_compensated) <= tol);
  }
}

TEST_CASE("Field of view and range limits hold", "[radar][geometry][property]") {
  const std::vector<SensorParams> rig = DefaultRig(4.5, 1.8);
  const int sensor = GENERATE(range(0, 5));
  const SensorParams& p = rig[sensor];
  const SensorModel window(p);
  const RadarModel exact(rig, ModelOptions{false, false, false, {}}, 5);
  const EgoMotion ego{Pose2{Position(100, -20), 0.7}, Velocity::Zero(), 0.0};
  const Pose2 pose = exact.SensorPose(sensor, ego.pose);
  int inside = 0, outside = 0;
  for (int i = 0; i < 300; ++i) {
    CounterRng rng(23, RngPurpose::kTest, sensor, i);
    // Half of the samples inside the field of view, half outside (up to all around).
    const double az = rng.Uniform(-std::min(kPi, p.fov), std::min(kPi, p.fov));
    const double range = rng.Uniform(0.0, 1.3 * p.max_range);
    // Skip a margin around the limits, where the 5 mm extent makes the answer ambiguous.
    if (std::abs(std::abs(az) - 0.5 * p.fov) < 0.01 || std::abs(range - p.max_range) < 0.1 ||
        std::abs(range - p.min_range) < 0.1)
      continue;
    const bool in = std::abs(az) < 0.5 * p.fov && range > p.min_range && range < p.max_range;
    const Position at = pose.ToParent(range * UnitVector(az));
    const OrientedBox ego_box{ego.pose.position, ego.pose.yaw, 4.5, 1.8};
    if (ego_box.Contains(at)) continue;
    const std::vector<Detection> dets =
        exact.ScanSensor(sensor, ego, OneTarget(at, Velocity::Zero(), 0.0), i);
    CHECK(dets.empty() != in);
    (in ? inside : outside)++;
  }
  CHECK(inside > 20);
  CHECK(outside > 20);

  // With noise and clutter: every reported detection lies inside the window.
  const RadarModel noisy(rig, ModelOptions{}, 6);
  Scene scene;
  for (int i = 0; i < 60; ++i) {
    CounterRng rng(29, RngPurpose::kTest, sensor, i);
    const Position at =
        pose.ToParent(rng.Uniform(0.0, 1.2 * p.max_range) * UnitVector(rng.Uniform(-kPi, kPi)));
    scene.targets.push_back({i, OrientedBox{at, rng.Uniform(-kPi, kPi), 4.5, 1.8},
                             rng.Uniform(-20.0, 20.0) * UnitVector(rng.Uniform(-kPi, kPi)), 0.0,
                             10.0});
  }
  int count = 0;
  for (int step = 0; step < 20; ++step) {
    for (const Detection& d : noisy.ScanSensor(sensor, ego, scene, step)) {
      ++count;
      CHECK(window.InWindow(Polar{d.range, d.azimuth, d.range_rate}));
    }
  }
  CHECK(count > 0);
}

TEST_CASE("A car behind a truck is hidden; only faces facing the sensor scatter",
          "[radar][geometry][occlusion]") {
  const std::vector<SensorParams> rig = DefaultRig(4.5, 1.8);
  const int front = 4;
  const EgoMotion ego{Pose2{Position::Zero(), 0.0}, Velocity(20.0, 0.0), 0.0};
  const Position sensor = SensorWorldPose(rig[front], ego.pose).position;
  const OrientedBox truck{Position(30.0, 0.0), 0.0, 12.0, 2.5};
  const double offset = GENERATE(range(-4.0, 4.01, 0.25));
  const OrientedBox car{Position(50.0, offset), 0.0, 4.5, 1.8};
  Scene scene;
  scene.targets.push_back({1, truck, Velocity(18.0, 0.0), 0.0, 20.0});
  scene.targets.push_back({2, car, Velocity(22.0, 0.0), 0.0, 10.0});

  const RadarModel model(rig, kExact, 8);
  int car_scatterers = 0;
  for (const Scatterer& sc : model.VisibleScatterers(front, ego, scene)) {
    if (sc.source_id != 2) continue;
    ++car_scatterers;
    // Independent check: no point of the sight line lies inside the truck.
    for (int k = 1; k < 200; ++k)
      REQUIRE_FALSE(truck.Contains(sensor + (k / 200.0) * (sc.position - sensor)));
    // Only faces whose outward normal points at the sensor: here the rear face (x = -L/2) and
    // the side facing the sensor's y.
    const Vector2 local = sc.position - car.center;
    const bool rear = std::abs(local.x() + 0.5 * car.length) < 1e-9;
    const bool side = std::abs(std::abs(local.y()) - 0.5 * car.width) < 1e-9 &&
                      local.y() * (sensor.y() - car.center.y()) > 0.0;
    CHECK((rear || side));
  }
  // The truck's front face (x = 24, half width 1.25) casts a shadow that widens with x; at the
  // car's rear face it spans |y| < 1.25 (x_rear - x_s) / (24 - x_s). A car entirely inside it is
  // hidden; one whose inner edge is outside it is partly seen.
  const double x_rear = car.center.x() - 0.5 * car.length;
  const double shadow = 1.25 * (x_rear - sensor.x()) / (24.0 - sensor.x());
  const bool hidden = std::abs(offset) + 0.5 * car.width < shadow - 1e-6;
  if (hidden) CHECK(car_scatterers == 0);
  if (std::abs(offset) - 0.5 * car.width > shadow) CHECK(car_scatterers > 0);
  // Detections follow suit; with occlusion switched off the car is seen.
  const std::vector<Detection> dets = model.ScanSensor(front, ego, scene, 0);
  const auto from_car =
      std::count_if(dets.begin(), dets.end(), [](const Detection& d) { return d.source_id == 2; });
  if (hidden) CHECK(from_car == 0);
  const RadarModel see_through(rig, ModelOptions{false, false, false, {}}, 8);
  const std::vector<Detection> all = see_through.ScanSensor(front, ego, scene, 0);
  CHECK(std::count_if(all.begin(), all.end(), [](const Detection& d) { return d.source_id == 2; }) >
        0);
}

TEST_CASE("Side radars see a parallel truck's flank with ~zero compensated speed",
          "[radar][geometry]") {
  const std::vector<SensorParams> rig = DefaultRig(4.5, 1.8);
  const double heading = GENERATE(-2.0, 0.0, 0.9);
  const Pose2 ego_pose{Position(250.0, -40.0), heading};
  const EgoMotion ego{ego_pose, 25.0 * UnitVector(heading), 0.0};
  const Velocity truck_v = 22.0 * UnitVector(heading);
  Scene scene;
  scene.targets.push_back({9,
                           OrientedBox{ego_pose.ToParent(Position(0.0, 3.6)), heading, 16.0, 2.5},
                           truck_v, 0.0, 20.0});
  const RadarModel model(rig, kExact, 4);
  int flank = 0;
  for (const int sensor : {0, 2}) {  // front_left, rear_left
    const std::vector<Detection> dets = model.ScanSensor(sensor, ego, scene, 0);
    REQUIRE_FALSE(dets.empty());
    for (const Detection& d : dets) {
      REQUIRE(d.source_id == 9);
      const Vector2 los = (d.position_world - d.sensor_position_world) / d.range;
      // A cell's scatterers span at most one azimuth cell: |mean u_i - centroid dir| <= dAz.
      CHECK(std::abs(d.radial_speed_compensated - truck_v.dot(los)) <=
            (truck_v - ego.velocity).norm() * rig[sensor].azimuth_resolution + 1e-9);
      if (std::abs(los.dot(UnitVector(heading))) < 0.1) {
        ++flank;
        CHECK(std::abs(d.radial_speed_compensated) < 22.0 * 0.1 + 0.2);
      }
    }
  }
  CHECK(flank > 0);
}

TEST_CASE("A rotating target's scatterers carry their rigid-body velocity", "[radar][geometry]") {
  const std::vector<SensorParams> rig = DefaultRig(4.5, 1.8);
  const double omega = GENERATE(-0.6, 0.4);
  const double box_yaw = GENERATE(0.2, 1.3, 2.9);
  const EgoMotion ego{Pose2{Position(10.0, 5.0), 0.4}, Velocity::Zero(), 0.0};
  const Velocity v(3.0, -2.0);
  const OrientedBox box{ego.pose.ToParent(Position(25.0, 1.0)), box_yaw, 5.0, 2.0};
  Scene scene;
  scene.targets.push_back({5, box, v, omega, 15.0});
  const RadarModel model(rig, kExact, 4);
  const int front = 4;
  const std::vector<Detection> dets = model.ScanSensor(front, ego, scene, 0);
  REQUIRE_FALSE(dets.empty());
  // Velocity is affine in position, so the SNR-weighted mean velocity of a cell is the velocity
  // at its centroid; only the spread of sight lines within one azimuth cell (<= dAz) remains.
  const double vmax = v.norm() + std::abs(omega) * 0.5 * std::hypot(5.0, 2.0);
  for (const Detection& d : dets) {
    const Vector2 los = (d.position_world - d.sensor_position_world) / d.range;
    const Velocity vp = RigidPointVelocity(v, omega, box.center, d.position_world);
    CHECK(std::abs(d.radial_speed_compensated - vp.dot(los)) <=
          vmax * rig[front].azimuth_resolution + 1e-9);
  }
}

TEST_CASE("Scan output does not depend on the thread count", "[radar][determinism]") {
  const std::vector<SensorParams> rig = DefaultRig(4.5, 1.8);
  const RadarModel model(rig, ModelOptions{}, 77);
  Scene scene;
  for (int i = 0; i < 50; ++i) {
    CounterRng rng(31, RngPurpose::kTest, 0, i);
    const double lane = -7.0 + 3.5 * (i % 5);
    const double x = rng.Uniform(-150.0, 150.0);
    const bool truck = i % 7 == 0;
    scene.targets.push_back(
        {100 + i, OrientedBox{Position(x, lane), 0.0, truck ? 16.0 : 4.5, truck ? 2.5 : 1.8},
         Velocity(rng.Uniform(20.0, 35.0), 0.0), 0.0, truck ? 20.0 : 10.0});
  }
  for (const double y : {-9.5, 9.5}) {
    Polyline rail{y > 0 ? 1 : 2, {}, -5.0};
    for (double x = -2000.0; x <= 2000.0; x += 50.0) rail.points.emplace_back(x, y);
    scene.polylines.push_back(rail);
  }
  const EgoMotion ego{Pose2{Position(0.0, 0.0), 0.0}, Velocity(27.0, 0.0), 0.01};
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const std::vector<Detection> a = model.Scan(ego, scene, 12, 0.6, 0.05);
  omp_set_num_threads(2);
  const std::vector<Detection> b = model.Scan(ego, scene, 12, 0.6, 0.05);
  omp_set_num_threads(threads);
  REQUIRE(a.size() == b.size());
  std::vector<int> per_sensor(rig.size(), 0);
  int rail = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    CHECK(a[i].sensor == b[i].sensor);
    CHECK(a[i].range == b[i].range);
    CHECK(a[i].azimuth == b[i].azimuth);
    CHECK(a[i].range_rate == b[i].range_rate);
    CHECK(a[i].source_id == b[i].source_id);
    per_sensor[a[i].sensor]++;
    rail += a[i].source_id == 1 || a[i].source_id == 2;
  }
  for (const int n : per_sensor) CHECK(n > 0);  // all five sensors report at t = 0.6 s
  CHECK(rail > 0);
  // Another step draws different noise.
  const std::vector<Detection> c = model.Scan(ego, scene, 13, 0.6, 0.05);
  CHECK((c.size() != a.size() || c[0].range != a[0].range));
}
