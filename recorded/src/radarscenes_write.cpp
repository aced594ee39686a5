// Writing a RadarScenes dataset root (docs/recorded-data.md, "Export").
#include <cstdio>
#include <fstream>
#include <map>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "dualgrid/recorded/radarscenes.hpp"
#include "h5.hpp"
#include "write_util.hpp"

namespace dualgrid::recorded {

namespace {

using Json = nlohmann::json;

}  // namespace

int LabelOfVClass(const std::string& c) {
  static const std::map<std::string, int> kLabels = {
      {"passenger", 0},  {"private", 0},    {"taxi", 0},       {"emergency", 0},
      {"authority", 0},  {"army", 0},       {"vip", 0},        {"hov", 0},
      {"evehicle", 0},   {"custom1", 10},   {"custom2", 10},   {"delivery", 1},
      {"truck", 2},      {"trailer", 2},    {"bus", 3},        {"coach", 3},
      {"tram", 4},       {"rail_urban", 4}, {"rail", 4},       {"rail_electric", 4},
      {"rail_fast", 4},  {"bicycle", 5},    {"moped", 6},      {"motorcycle", 6},
      {"pedestrian", 7}, {"ship", 10},      {"container", 10}, {"cable_car", 10},
      {"subway", 4},     {"aircraft", 10},  {"wheelchair", 7}, {"scooter", 6},
      {"drone", 10}};
  const auto it = kLabels.find(c);
  return it == kLabels.end() ? 10 : it->second;  // 10: other
}

void WriteRadarScenes(const RecordedSequence& seq, const std::filesystem::path& root, double a) {
  h5::Silence();
  const std::filesystem::path dir = root / "data" / seq.name;
  std::filesystem::create_directories(dir);

  // sensors.json: car coordinates (rear axle, a behind the box centre); dualgrid's keys keep
  // what the public schema has no field for.
  Json sensors;
  for (std::size_t k = 0; k < seq.sensors.size(); ++k) {
    const radar::SensorParams& s = seq.sensors[k];
    sensors["radar_" + std::to_string(k + 1)] = {{"id", k + 1},
                                                 {"x", s.mount.position.x() + a},
                                                 {"y", s.mount.position.y()},
                                                 {"yaw", s.mount.yaw},
                                                 {"dualgrid_name", s.name},
                                                 {"dualgrid_fov", s.fov},
                                                 {"dualgrid_min_range", s.min_range},
                                                 {"dualgrid_max_range", s.max_range}};
  }
  sensors["dualgrid_ego"] = {
      {"length", seq.ego_length}, {"width", seq.ego_width}, {"rear_axle_to_centre", a}};
  WriteJson(root / "sensors.json", sensors);

  // Scenes are keyed by timestamp: scans sharing one get 1 us apart, in their order.
  std::vector<std::int64_t> stamp(seq.scans.size());
  for (std::size_t i = 0; i < seq.scans.size(); ++i) {
    stamp[i] = seq.scans[i].timestamp_us;
    if (i > 0 && stamp[i] <= stamp[i - 1]) stamp[i] = stamp[i - 1] + 1;
  }
  WriteJson(root / "sequences.json",
            {{"sequences",
              {{seq.name,
                {{"category", "validation"},
                 {"scenes", seq.scans.size()},
                 {"duration", seq.scans.empty() ? 0.0 : (stamp.back() - stamp.front()) / 1e6}}}}}});

  Json scenes;
  std::map<int, std::int64_t> last_of_sensor;
  for (std::size_t i = 0; i < seq.scans.size(); ++i) {
    const RecordedScan& s = seq.scans[i];
    const auto prev = last_of_sensor.find(s.sensor);
    Json e = {{"sensor_id", s.sensor + 1},
              {"radar_indices", {s.begin, s.end}},
              {"odometry_index", i},
              {"odometry_timestamp", stamp[i]},
              {"prev_timestamp", i > 0 ? Json(stamp[i - 1]) : Json(nullptr)},
              {"next_timestamp", i + 1 < stamp.size() ? Json(stamp[i + 1]) : Json(nullptr)},
              {"prev_timestamp_same_sensor",
               prev != last_of_sensor.end() ? Json(prev->second) : Json(nullptr)},
              {"next_timestamp_same_sensor", nullptr},
              {"image_name", ""}};
    if (prev != last_of_sensor.end())
      scenes[std::to_string(prev->second)]["next_timestamp_same_sensor"] = stamp[i];
    scenes[std::to_string(stamp[i])] = e;
    last_of_sensor[s.sensor] = stamp[i];
  }
  WriteJson(dir / "scenes.json", {{"sequence_name", seq.name},
                                  {"first_timestamp", stamp.empty() ? 0 : stamp.front()},
                                  {"last_timestamp", stamp.empty() ? 0 : stamp.back()},
                                  {"scenes", scenes}});

  const std::string h5_name = (dir / "radar_data.h5").string();
  const h5::Id file(H5Fcreate(h5_name.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
  if (!file.valid()) throw std::runtime_error(h5_name + ": cannot be created");

  // radar_data: one row per detection, in scan order (the scans' [begin, end) ranges).
  const std::size_t n = seq.points.size();
  std::vector<std::uint64_t> t(n);
  std::vector<std::uint8_t> sensor(n), label(n);
  std::vector<double> range(n), az(n), rcs(n), vr(n), vrc(n), xcc(n), ycc(n), xs(n), ys(n);
  std::vector<std::string> uuid(n), track(n);
  std::size_t track_len = 1;
  for (const std::string& name : seq.track_names) track_len = std::max(track_len, name.size());
  for (std::size_t k = 0; k < seq.scans.size(); ++k) {
    const RecordedScan& s = seq.scans[k];
    const Pose2 car{s.ego_pose.position - a * UnitVector(s.ego_pose.yaw), s.ego_pose.yaw};
    for (std::size_t i = s.begin; i < s.end; ++i) {
      const RecordedPoint& p = seq.points[i];
      t[i] = static_cast<std::uint64_t>(stamp[k]);
      sensor[i] = static_cast<std::uint8_t>(s.sensor + 1);
      range[i] = p.range;
      az[i] = p.azimuth;
      rcs[i] = p.rcs;
      vr[i] = p.range_rate;
      vrc[i] = p.radial_speed;
      const Position cc = car.ToLocal(p.position);
      xcc[i] = cc.x();
      ycc[i] = cc.y();
      xs[i] = p.position.x();
      ys[i] = p.position.y();
      uuid[i] = HexId(seq.name, i);
      track[i] = p.track >= 0 ? seq.track_names[p.track] : "";
      label[i] = static_cast<std::uint8_t>(p.label >= 0 ? p.label : kStaticLabel);
    }
  }
  h5::CompoundWriter r;
  r.AddUInt64("timestamp");
  r.AddUInt8("sensor_id");
  for (const char* f :
       {"range_sc", "azimuth_sc", "rcs", "vr", "vr_compensated", "x_cc", "y_cc", "x_seq", "y_seq"})
    r.AddDouble(f);
  r.AddString("uuid", 32);
  r.AddString("track_id", track_len);
  r.AddUInt8("label_id");
  r.Create(file.get(), h5_name, "radar_data", n);
  r.WriteUInt64("timestamp", t);
  r.WriteUInt8("sensor_id", sensor);
  r.WriteDoubles("range_sc", range);
  r.WriteDoubles("azimuth_sc", az);
  r.WriteDoubles("rcs", rcs);
  r.WriteDoubles("vr", vr);
  r.WriteDoubles("vr_compensated", vrc);
  r.WriteDoubles("x_cc", xcc);
  r.WriteDoubles("y_cc", ycc);
  r.WriteDoubles("x_seq", xs);
  r.WriteDoubles("y_seq", ys);
  r.WriteStrings("uuid", uuid);
  r.WriteStrings("track_id", track);
  r.WriteUInt8("label_id", label);

  // odometry: one row per scan, at its timestamp: the rear axle's pose, longitudinal speed and
  // yaw rate; dualgrid_lane_yaw (the road's direction, for the grid that follows it) is ours.
  const std::size_t m = seq.scans.size();
  std::vector<std::uint64_t> ot(m);
  std::vector<double> ox(m), oy(m), oyaw(m), ovx(m), owz(m), olane(m);
  for (std::size_t k = 0; k < m; ++k) {
    const RecordedScan& s = seq.scans[k];
    const Vector2 heading = UnitVector(s.ego_pose.yaw);
    const Position rear = s.ego_pose.position - a * heading;
    ot[k] = static_cast<std::uint64_t>(stamp[k]);
    ox[k] = rear.x();
    oy[k] = rear.y();
    oyaw[k] = s.ego_pose.yaw;
    ovx[k] = s.ego_velocity.dot(heading);
    owz[k] = s.ego_yaw_rate;
    olane[k] = s.lane_yaw;
  }
  h5::CompoundWriter o;
  o.AddUInt64("timestamp");
  for (const char* f : {"x_seq", "y_seq", "yaw_seq", "vx", "yaw_rate", "dualgrid_lane_yaw"})
    o.AddDouble(f);
  o.Create(file.get(), h5_name, "odometry", m);
  o.WriteUInt64("timestamp", ot);
  o.WriteDoubles("x_seq", ox);
  o.WriteDoubles("y_seq", oy);
  o.WriteDoubles("yaw_seq", oyaw);
  o.WriteDoubles("vx", ovx);
  o.WriteDoubles("yaw_rate", owz);
  o.WriteDoubles("dualgrid_lane_yaw", olane);
  if (H5Fflush(file.get(), H5F_SCOPE_GLOBAL) < 0)
    throw std::runtime_error("cannot write " + h5_name + ": " + SystemReason());
}

}  // namespace dualgrid::recorded
