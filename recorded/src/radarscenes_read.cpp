// Reading a RadarScenes sequence (docs/recorded-data.md, "The schema as read").
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "dualgrid/core/input_file.hpp"
#include "dualgrid/core/json_input.hpp"
#include "dualgrid/recorded/radarscenes.hpp"
#include "h5.hpp"

namespace dualgrid::recorded {

namespace {

using Json = nlohmann::json;

[[noreturn]] void Bad(const std::filesystem::path& file, const std::string& what) {
  throw std::invalid_argument(file.string() + ": " + what);
}

// `what` names the file's role in errors ("RadarScenes sensors file").
Json ReadJson(const std::filesystem::path& file, const std::string& what) {
  return ReadJsonInput(file, what);
}

// A value as a message shows it: its JSON text, at most 40 bytes.
std::string Shown(const Json& value) {
  const std::string text = value.dump(-1, ' ', true, Json::error_handler_t::replace);
  return text.size() > 40 ? text.substr(0, 40) + "..." : text;
}

double Number(const std::filesystem::path& file, const Json& obj, const std::string& key,
              const std::string& where) {
  const auto it = obj.find(key);
  if (it == obj.end()) Bad(file, "key '" + where + key + "' is missing");
  if (!it->is_number() || !std::isfinite(it->get<double>()))
    Bad(file, "key '" + where + key + "': expected a finite number, got " + Shown(*it));
  return it->get<double>();
}

std::int64_t Integer(const std::filesystem::path& file, const Json& obj, const std::string& key,
                     const std::string& where) {
  const auto it = obj.find(key);
  if (it == obj.end()) Bad(file, "key '" + where + key + "' is missing");
  if (!it->is_number_integer() ||
      (it->is_number_unsigned() &&
       it->get<std::uint64_t>() > std::uint64_t{std::numeric_limits<std::int64_t>::max()}))
    Bad(file, "key '" + where + key + "': expected an integer below 2^63, got " + Shown(*it));
  return it->get<std::int64_t>();
}

struct Rig {
  std::vector<radar::SensorParams> sensors;
  double length = kDefaultEgoLength, width = kDefaultEgoWidth;
  double rear_axle_to_centre = kDefaultRearAxleToCentre;
};

// sensors.json: radar_1 .. radar_N (consecutive), each {x, y, yaw} in car coordinates (rear
// axle); dualgrid's own keys (dualgrid_ego, dualgrid_fov, ...) are optional.
Rig ReadSensors(const std::filesystem::path& file) {
  const Json j = ReadJson(file, "RadarScenes sensors file");
  if (!j.is_object()) Bad(file, "expected a JSON object of radar_1, radar_2, ...");
  Rig rig;
  if (const auto e = j.find("dualgrid_ego"); e != j.end()) {
    if (!e->is_object()) Bad(file, "key 'dualgrid_ego': expected an object");
    rig.length = Number(file, *e, "length", "dualgrid_ego.");
    rig.width = Number(file, *e, "width", "dualgrid_ego.");
    rig.rear_axle_to_centre = Number(file, *e, "rear_axle_to_centre", "dualgrid_ego.");
    if (const std::string e = EgoSizeError(rig.length, rig.width); !e.empty())
      Bad(file, "key 'dualgrid_ego': " + e);
    if (std::abs(rig.rear_axle_to_centre) > rig.length)
      Bad(file, "key 'dualgrid_ego.rear_axle_to_centre': expected within +-length (" +
                    std::to_string(rig.length) + " m)");
  }
  for (int k = 1;; ++k) {
    const std::string name = "radar_" + std::to_string(k);
    const auto it = j.find(name);
    if (it == j.end()) break;
    if (!it->is_object()) Bad(file, "key '" + name + "': expected an object {x, y, yaw}");
    radar::SensorParams s;
    s.name = name;
    if (const auto n = it->find("dualgrid_name"); n != it->end()) {
      if (!n->is_string()) Bad(file, "key '" + name + ".dualgrid_name': expected a string");
      s.name = n->get<std::string>();
    }
    const std::string w = name + ".";
    s.mount.position = {Number(file, *it, "x", w) - rig.rear_axle_to_centre,
                        Number(file, *it, "y", w)};
    s.mount.yaw = Number(file, *it, "yaw", w);
    // RadarScenes' radars as we read the data paper: +-60 deg, up to 100 m.
    s.fov = it->contains("dualgrid_fov") ? Number(file, *it, "dualgrid_fov", w) : DegToRad(120.0);
    s.min_range =
        it->contains("dualgrid_min_range") ? Number(file, *it, "dualgrid_min_range", w) : 0.5;
    s.max_range =
        it->contains("dualgrid_max_range") ? Number(file, *it, "dualgrid_max_range", w) : 100.0;
    std::string error;
    if (!s.IsValid(&error)) Bad(file, "key '" + name + "': " + error);
    rig.sensors.push_back(s);
  }
  if (rig.sensors.empty()) Bad(file, "key 'radar_1' is missing (no radars)");
  return rig;
}

struct SceneEntry {
  std::int64_t timestamp = 0;
  int sensor_id = 0;
  std::int64_t begin = 0, end = 0;
  std::int64_t odometry_index = 0;
};

std::vector<SceneEntry> ReadScenes(const std::filesystem::path& file, std::string* name,
                                   std::size_t sensors) {
  const Json j = ReadJson(file, "RadarScenes scenes file");
  if (!j.is_object()) Bad(file, "expected a JSON object with sequence_name and scenes");
  const auto seq = j.find("sequence_name");
  if (seq == j.end() || !seq->is_string()) Bad(file, "key 'sequence_name': expected a string");
  *name = seq->get<std::string>();
  const std::int64_t first = Integer(file, j, "first_timestamp", "");
  const std::int64_t last = Integer(file, j, "last_timestamp", "");
  const auto scenes = j.find("scenes");
  if (scenes == j.end() || !scenes->is_object()) Bad(file, "key 'scenes': expected an object");
  std::vector<SceneEntry> out;
  for (const auto& [key, s] : scenes->items()) {
    const std::string w = "scenes." + key + ".";
    SceneEntry e;
    std::size_t used = 0;
    try {
      e.timestamp = std::stoll(key, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != key.size() || e.timestamp < 0)
      Bad(file, "key 'scenes." + key + "': expected a timestamp in microseconds as the key");
    if (!s.is_object()) Bad(file, "key 'scenes." + key + "': expected an object");
    const std::int64_t sid = Integer(file, s, "sensor_id", w);
    if (sid < 1 || sid > static_cast<std::int64_t>(sensors))
      Bad(file, "key '" + w + "sensor_id': " + std::to_string(sid) + " has no radar_" +
                    std::to_string(sid) + " in sensors.json (1.." + std::to_string(sensors) + ")");
    e.sensor_id = static_cast<int>(sid);
    const auto idx = s.find("radar_indices");
    if (idx == s.end() || !idx->is_array() || idx->size() != 2 || !(*idx)[0].is_number_integer() ||
        !(*idx)[1].is_number_integer())
      Bad(file, "key '" + w + "radar_indices': expected [start, end] integers");
    e.begin = (*idx)[0].get<std::int64_t>();
    e.end = (*idx)[1].get<std::int64_t>();
    e.odometry_index = Integer(file, s, "odometry_index", w);
    out.push_back(e);
  }
  if (out.empty()) Bad(file, "key 'scenes': no scenes (an empty sequence)");
  std::sort(out.begin(), out.end(),
            [](const SceneEntry& a, const SceneEntry& b) { return a.timestamp < b.timestamp; });
  if (out.front().timestamp != first || out.back().timestamp != last)
    Bad(file, "keys 'first_timestamp'/'last_timestamp' (" + std::to_string(first) + "/" +
                  std::to_string(last) + ") are not the first and last scene's (" +
                  std::to_string(out.front().timestamp) + "/" +
                  std::to_string(out.back().timestamp) + ")");
  return out;
}

RecordedSequence ReadSequence(const std::filesystem::path& sequence_dir,
                              const std::optional<std::filesystem::path>& sensors_json) {
  std::filesystem::path dir = sequence_dir.lexically_normal();
  if (dir.filename().empty()) dir = dir.parent_path();  // a trailing '/'
  CheckInputFolder(dir, "RadarScenes sequence");
  const std::filesystem::path sensors_file =
      sensors_json ? *sensors_json
                   : std::filesystem::absolute(dir).parent_path().parent_path() / "sensors.json";
  const Rig rig = ReadSensors(sensors_file);
  RecordedSequence seq;
  const std::filesystem::path scenes_file = dir / "scenes.json";
  const std::vector<SceneEntry> scenes = ReadScenes(scenes_file, &seq.name, rig.sensors.size());
  seq.sensors = rig.sensors;
  seq.ego_length = rig.length;
  seq.ego_width = rig.width;

  const std::filesystem::path h5_file = dir / "radar_data.h5";
  const std::string h5_name = h5_file.string();
  CheckInputFile(h5_file, "RadarScenes radar data");
  if (H5Fis_hdf5(h5_name.c_str()) <= 0) Bad(h5_file, "not an HDF5 file (truncated or damaged?)");
  const h5::Id file(H5Fopen(h5_name.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!file.valid()) Bad(h5_file, "cannot be opened as HDF5 (truncated or damaged?)");

  // Odometry: the ego's rear axle in sequence coordinates.
  const h5::CompoundReader odo(file.get(), h5_name, "odometry");
  const auto o_t = odo.Ints("timestamp");
  const auto o_x = odo.Doubles("x_seq");
  const auto o_y = odo.Doubles("y_seq");
  const auto o_yaw = odo.Doubles("yaw_seq");
  const auto o_vx = odo.Doubles("vx");
  const auto o_wz = odo.Doubles("yaw_rate");
  const bool has_lane = odo.Has("dualgrid_lane_yaw");
  const auto o_lane = has_lane ? odo.Doubles("dualgrid_lane_yaw") : o_yaw;
  const std::string odo_where = "dataset 'odometry', ";
  for (std::size_t i = 0; i < odo.size(); ++i) {
    if (i > 0 && o_t[i] <= o_t[i - 1])
      Bad(h5_file, odo_where + "field 'timestamp': not increasing at row " + std::to_string(i) +
                       " (" + std::to_string(o_t[i - 1]) + " then " + std::to_string(o_t[i]) + ")");
    const std::pair<const char*, double> values[] = {
        {"x_seq", o_x[i]}, {"y_seq", o_y[i]},     {"yaw_seq", o_yaw[i]},
        {"vx", o_vx[i]},   {"yaw_rate", o_wz[i]}, {"dualgrid_lane_yaw", o_lane[i]}};
    for (const auto& [field, v] : values)
      if (!std::isfinite(v))
        Bad(h5_file, odo_where + "field '" + field + "': not finite at row " + std::to_string(i));
  }

  const h5::CompoundReader rd(file.get(), h5_name, "radar_data");
  const auto r_t = rd.Ints("timestamp");
  const auto r_sensor = rd.Ints("sensor_id");
  const auto r_range = rd.Doubles("range_sc");
  const auto r_az = rd.Doubles("azimuth_sc");
  const auto r_rcs = rd.Doubles("rcs");
  const auto r_vr = rd.Doubles("vr");
  const auto r_vrc = rd.Doubles("vr_compensated");
  const auto r_x = rd.Doubles("x_seq");
  const auto r_y = rd.Doubles("y_seq");
  seq.has_labels = rd.Has("label_id");
  const auto r_label = seq.has_labels ? rd.Ints("label_id") : std::vector<std::int64_t>();
  const bool has_tracks = rd.Has("track_id");
  const auto r_track = has_tracks ? rd.Strings("track_id") : std::vector<std::string>();

  const std::string rd_where = "dataset 'radar_data', ";
  const auto n = static_cast<std::int64_t>(rd.size());
  std::map<std::string, int> track_index;
  std::int64_t prev_end = 0;
  for (const SceneEntry& s : scenes) {
    const std::string scene = "scene " + std::to_string(s.timestamp);
    if (s.begin < 0 || s.end < s.begin || s.end > n)
      Bad(scenes_file, "key 'scenes." + std::to_string(s.timestamp) + ".radar_indices': [" +
                           std::to_string(s.begin) + ", " + std::to_string(s.end) +
                           ") is not a range inside radar_data's " + std::to_string(n) + " rows");
    if (s.begin < prev_end)
      Bad(scenes_file, "key 'scenes." + std::to_string(s.timestamp) + ".radar_indices': [" +
                           std::to_string(s.begin) + ", " + std::to_string(s.end) +
                           ") overlaps the previous scene's rows (up to " +
                           std::to_string(prev_end) + ")");
    prev_end = s.end;
    if (s.odometry_index < 0 || s.odometry_index >= static_cast<std::int64_t>(odo.size()))
      Bad(scenes_file, "key 'scenes." + std::to_string(s.timestamp) +
                           ".odometry_index': " + std::to_string(s.odometry_index) +
                           " is outside odometry's " + std::to_string(odo.size()) + " rows");
    RecordedScan scan;
    scan.timestamp_us = s.timestamp;
    scan.sensor = s.sensor_id - 1;
    const auto k = static_cast<std::size_t>(s.odometry_index);
    const double yaw = o_yaw[k];
    const Vector2 heading = UnitVector(yaw);
    // RadarScenes' car origin is the rear axle; dualgrid's ego frame is the box centre.
    scan.ego_pose = {Position(o_x[k], o_y[k]) + rig.rear_axle_to_centre * heading, yaw};
    scan.ego_velocity = Rotation(yaw) * Vector2(o_vx[k], o_wz[k] * rig.rear_axle_to_centre);
    scan.ego_yaw_rate = o_wz[k];
    scan.lane_yaw = o_lane[k];
    scan.begin = seq.points.size();
    for (std::int64_t i = s.begin; i < s.end; ++i) {
      const std::string row = " at row " + std::to_string(i) + " (" + scene + ")";
      if (r_t[i] != s.timestamp)
        Bad(h5_file, rd_where + "field 'timestamp': " + std::to_string(r_t[i]) + row +
                         " differs from its scene's timestamp");
      if (r_sensor[i] != s.sensor_id)
        Bad(h5_file, rd_where + "field 'sensor_id': " + std::to_string(r_sensor[i]) + row +
                         " differs from its scene's sensor " + std::to_string(s.sensor_id));
      int label = -1;
      if (seq.has_labels) {
        if (r_label[i] < 0 || r_label[i] > kStaticLabel)
          Bad(h5_file, rd_where + "field 'label_id': " + std::to_string(r_label[i]) + row +
                           " is not a RadarScenes label (0-11)");
        label = static_cast<int>(r_label[i]);
      }
      // The last detections of some published sequences hold NaN: skipped and counted.
      if (!std::isfinite(r_x[i]) || !std::isfinite(r_y[i]) || !std::isfinite(r_vrc[i]) ||
          !std::isfinite(r_az[i]) || !std::isfinite(r_range[i]) || !std::isfinite(r_vr[i])) {
        ++seq.skipped_points;
        continue;
      }
      RecordedPoint p;
      p.range = r_range[i];
      p.azimuth = r_az[i];
      p.range_rate = r_vr[i];
      p.radial_speed = r_vrc[i];
      p.rcs = std::isfinite(r_rcs[i]) ? r_rcs[i] : 0.0;
      p.position = {r_x[i], r_y[i]};
      p.label = label;
      if (has_tracks && !r_track[i].empty()) {
        const auto [it, inserted] =
            track_index.try_emplace(r_track[i], static_cast<int>(seq.track_names.size()));
        if (inserted) seq.track_names.push_back(r_track[i]);
        p.track = it->second;
      }
      seq.points.push_back(p);
    }
    scan.end = seq.points.size();
    seq.scans.push_back(scan);
  }
  const std::int64_t t0 = seq.scans.front().timestamp_us;
  seq.time_origin_us = t0 - t0 % 1000000;
  return seq;
}

}  // namespace

RecordedSequence ReadRadarScenes(const std::filesystem::path& sequence_dir,
                                 const std::optional<std::filesystem::path>& sensors_json) {
  h5::Silence();
  return ReadingJsonInput(sequence_dir, "RadarScenes sequence",
                          [&] { return ReadSequence(sequence_dir, sensors_json); });
}

}  // namespace dualgrid::recorded
