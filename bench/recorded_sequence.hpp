// The recorded sequence of the recorded benchmarks (bench_recorded, bench_floor_e2e): 20 s, four
// radars at ~13.3 Hz each, about 50 detections per scan, as the published RadarScenes data average.
#pragma once

#include <cmath>
#include <string>

#include "dualgrid/core/random.hpp"
#include "dualgrid/cosim/recorded_source.hpp"

namespace dualgrid::bench {

constexpr double kSequenceDuration = 20.0;  // [s]

// A sequence like the published ones: the ego at 10 m/s, cars passing, static returns around.
inline cosim::RecordedSequence MakeSequence() {
  cosim::RecordedSequence s;
  s.name = "sequence_bench";
  const double mounts[4][3] = {{3.663 - 1.45, -0.873, -1.484},
                               {3.86 - 1.45, -0.70, -0.436},
                               {3.86 - 1.45, 0.70, 0.436},
                               {3.663 - 1.45, 0.873, 1.484}};
  for (int k = 0; k < 4; ++k) {
    radar::SensorParams p;
    p.name = "radar_" + std::to_string(k + 1);
    p.mount = {{mounts[k][0], mounts[k][1]}, mounts[k][2]};
    p.fov = DegToRad(120.0);
    p.max_range = 100.0;
    s.sensors.push_back(p);
  }
  s.track_names = {"car-1", "car-2", "car-3"};
  s.has_labels = true;
  CounterRng rng(1, RngPurpose::kTest, 0, 0);
  auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * rng.Uniform(); };
  std::int64_t t_us = 1'000'000;
  for (int i = 0; t_us < 1'000'000 + static_cast<std::int64_t>(kSequenceDuration * 1e6); ++i) {
    const double t = (t_us - 1'000'000) / 1e6;
    cosim::RecordedScan scan;
    scan.timestamp_us = t_us;
    scan.sensor = i % 4;
    scan.ego_pose = {{10.0 * t, 0.0}, 0.0};
    scan.ego_velocity = {10.0, 0.0};
    scan.begin = s.points.size();
    const Pose2 sensor = scan.ego_pose.Compose(s.sensors[scan.sensor].mount);
    for (int d = 0; d < 50; ++d) {
      cosim::RecordedPoint p;
      const int track = d < 12 ? d / 4 : -1;
      Position pos;
      Velocity v = Velocity::Zero();
      if (track >= 0) {  // three cars at 15, 12, 18 m/s on the lanes beside the ego
        const double speed = 12.0 + 3.0 * track;
        pos = {20.0 + 15.0 * track + speed * t + uniform(-2, 2),
               (track - 1) * 3.5 + uniform(-0.8, 0.8)};
        v = {speed, 0.0};
      } else {
        pos = sensor.ToParent(uniform(2, 80) * UnitVector(uniform(-1.0, 1.0)));
      }
      const Vector2 rel = pos - sensor.position;
      p.range = rel.norm();
      p.azimuth = WrapAngle(std::atan2(rel.y(), rel.x()) - sensor.yaw);
      const Vector2 u = rel / p.range;
      p.radial_speed = v.dot(u);
      p.range_rate = p.radial_speed - scan.ego_velocity.dot(u);
      p.position = pos;
      p.label = track >= 0 ? 0 : cosim::kStaticLabel;
      p.track = track;
      s.points.push_back(p);
    }
    scan.end = s.points.size();
    s.scans.push_back(scan);
    t_us += 18'750;  // 4 radars x 13.3 Hz
  }
  s.time_origin_us = 1'000'000;
  return s;
}

}  // namespace dualgrid::bench
