// Writing a recorded sequence as a nuScenes version folder (docs/recorded-data.md, "nuScenes",
// "Export").
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <stdexcept>

#include "dualgrid/recorded/nuscenes.hpp"
#include "dualgrid/recorded/pcd.hpp"
#include "dualgrid/recorded/radarscenes.hpp"
#include "write_util.hpp"

namespace dualgrid::recorded {

namespace {

using Json = nlohmann::json;

// The export's clock: simulated time 0 is this Unix time [us] (2020-09-13), a whole second, so
// the reader's time origin gives the run's times back.
constexpr std::int64_t kEpochUs = 1'600'000'000'000'000;

Json Quaternion(double yaw) {
  return Json::array({std::cos(0.5 * yaw), 0.0, 0.0, std::sin(0.5 * yaw)});
}

// The channel of each sensor: the assignment of the five sensors to the channels' directions
// (front 0, corners +-45 deg and +-135 deg) with the least summed angle.
std::vector<int> Channels(const std::vector<radar::SensorParams>& sensors) {
  if (sensors.size() != 5)
    throw std::invalid_argument("export --format nuscenes: the run has " +
                                std::to_string(sensors.size()) +
                                " radars; nuScenes has five channels (front and four corners)");
  const double nominal[5] = {0.0, 0.25 * kPi, -0.25 * kPi, 0.75 * kPi, -0.75 * kPi};
  std::array<int, 5> perm = {0, 1, 2, 3, 4}, best = perm;
  double best_cost = std::numeric_limits<double>::infinity();
  do {
    double cost = 0.0;
    for (int s = 0; s < 5; ++s)
      cost += std::abs(WrapAngle(sensors[s].mount.yaw - nominal[perm[s]]));
    if (cost < best_cost) best_cost = cost, best = perm;
  } while (std::next_permutation(perm.begin(), perm.end()));
  return {best.begin(), best.end()};
}

// The devkit's 18 radar fields, with the sizes and types of the published files.
PcdCloud RadarCloud(const RecordedSequence& seq, const RecordedScan& s, bool float64) {
  PcdCloud c;
  const char* names[] = {"x",
                         "y",
                         "z",
                         "dyn_prop",
                         "id",
                         "rcs",
                         "vx",
                         "vy",
                         "vx_comp",
                         "vy_comp",
                         "is_quality_valid",
                         "ambig_state",
                         "x_rms",
                         "y_rms",
                         "invalid_state",
                         "pdh0",
                         "vx_rms",
                         "vy_rms"};
  const int sizes[] = {4, 4, 4, 1, 2, 4, 4, 4, 4, 4, 1, 1, 1, 1, 1, 1, 1, 1};
  const char types[] = {'F', 'F', 'F', 'I', 'I', 'F', 'F', 'F', 'F',
                        'F', 'I', 'I', 'I', 'I', 'I', 'I', 'I', 'I'};
  for (int f = 0; f < 18; ++f)
    c.fields.push_back({names[f], types[f], float64 && types[f] == 'F' ? 8 : sizes[f]});
  c.columns.assign(18, {});
  auto row = [&](std::array<double, 18> v) {
    for (int f = 0; f < 18; ++f) c.columns[f].push_back(v[f]);
  };
  if (s.begin == s.end) {  // the devkit's empty cloud: one point with NaN coordinates
    const double nan = std::numeric_limits<double>::quiet_NaN();
    row({nan, nan, nan, 0, 0, nan, nan, nan, nan, nan, 0, 0, 0, 0, 0, 0, 0, 0});
    return c;
  }
  for (std::size_t i = s.begin; i < s.end; ++i) {
    const RecordedPoint& p = seq.points[i];
    const double cx = std::cos(p.azimuth), cy = std::sin(p.azimuth);
    const double dyn = std::abs(p.radial_speed) > 0.5 ? 0 : 1;  // moving, stationary
    row({p.range * cx, p.range * cy, 0.0, dyn, static_cast<double>(i - s.begin), p.rcs,
         p.range_rate * cx, p.range_rate * cy, p.radial_speed * cx, p.radial_speed * cy, 1, 3, 0, 0,
         0, 1, 0, 0});
  }
  return c;
}

struct Writer {
  const RecordedSequence& seq;
  std::filesystem::path root;
  std::string scene;
  bool float64 = false;
  double a = 0.0;  // rear axle to box centre [m]
  std::vector<int> channel;
  std::map<std::string, Json> tables;

  std::string Token(const std::string& kind, std::size_t i) const {
    return HexId(scene + "/" + kind, i);
  }
  void Fixed(const std::vector<NuScenesKeyFrame>& keys);
  void Samples(const std::vector<NuScenesKeyFrame>& keys, std::vector<std::size_t>* sample_of_scan,
               std::vector<bool>* key);
  void SampleData(const std::vector<std::size_t>& sample_of_scan, const std::vector<bool>& key);
  void Annotations(const std::vector<NuScenesKeyFrame>& keys,
                   const std::vector<std::size_t>& sample_of_scan, const std::vector<bool>& key);
};

// The tables of fixed content: sensors, calibration, log, map, visibility, attributes, scene.
void Writer::Fixed(const std::vector<NuScenesKeyFrame>& keys) {
  for (int s = 0; s < 5; ++s) {
    const std::string ch = kNuScenesChannels[channel[s]];
    const radar::SensorParams& p = seq.sensors[s];
    tables["sensor"].push_back(
        {{"token", Token("sensor", s)}, {"channel", ch}, {"modality", "radar"}});
    tables["calibrated_sensor"].push_back(
        {{"token", Token("calibrated_sensor", s)},
         {"sensor_token", Token("sensor", s)},
         {"translation", {p.mount.position.x() + a, p.mount.position.y(), 0.5}},
         {"rotation", Quaternion(p.mount.yaw)},
         {"camera_intrinsic", Json::array()}});
  }
  tables["log"] = Json::array({{{"token", Token("log", 0)},
                                {"logfile", seq.name},
                                {"vehicle", "dualgrid"},
                                {"date_captured", "2020-09-13"},
                                {"location", "dualgrid-simulation"}}});
  tables["map"] = Json::array({{{"token", Token("map", 0)},
                                {"log_tokens", {Token("log", 0)}},
                                {"category", "semantic_prior"},
                                {"filename", ""}}});
  const char* levels[] = {"v0-40", "v40-60", "v60-80", "v80-100"};
  for (int v = 0; v < 4; ++v)
    tables["visibility"].push_back(
        {{"token", std::to_string(v + 1)}, {"level", levels[v]}, {"description", levels[v]}});
  for (const char* name : {"vehicle.moving", "vehicle.stopped", "vehicle.parked"})
    tables["attribute"].push_back({{"token", HexId(std::string("attribute/") + name, 0)},
                                   {"name", name},
                                   {"description", name}});
  tables["scene"] = Json::array({{{"token", Token("scene", 0)},
                                  {"name", scene},
                                  {"description", "dualgrid export of run " + seq.name},
                                  {"log_token", Token("log", 0)},
                                  {"nbr_samples", keys.size()},
                                  {"first_sample_token", Token("sample", 0)},
                                  {"last_sample_token", Token("sample", keys.size() - 1)}}});
}

// The samples (one per key frame) and, per scan, its sample (a key frame's own, else the next
// one after it, else the last) and whether it is its channel's key frame of that sample.
void Writer::Samples(const std::vector<NuScenesKeyFrame>& keys,
                     std::vector<std::size_t>* sample_of_scan, std::vector<bool>* key) {
  for (std::size_t k = 0; k < keys.size(); ++k)
    tables["sample"].push_back({{"token", Token("sample", k)},
                                {"timestamp", kEpochUs + keys[k].timestamp_us},
                                {"scene_token", Token("scene", 0)},
                                {"prev", k > 0 ? Token("sample", k - 1) : ""},
                                {"next", k + 1 < keys.size() ? Token("sample", k + 1) : ""}});
  const auto& scans = seq.scans;
  sample_of_scan->assign(scans.size(), keys.size() - 1);
  key->assign(scans.size(), false);
  for (std::size_t i = 0; i < scans.size(); ++i)
    for (std::size_t k = 0; k < keys.size(); ++k)
      if (keys[k].timestamp_us >= scans[i].timestamp_us) {
        (*sample_of_scan)[i] = k;
        break;
      }
  for (std::size_t k = 0; k < keys.size(); ++k)
    for (int s = 0; s < 5; ++s) {  // the sensor's scan nearest the key frame
      std::size_t best = scans.size();
      for (std::size_t i = 0; i < scans.size(); ++i)
        if (scans[i].sensor == s &&
            (best == scans.size() ||
             std::llabs(scans[i].timestamp_us - keys[k].timestamp_us) <
                 std::llabs(scans[best].timestamp_us - keys[k].timestamp_us)))
          best = i;
      if (best < scans.size() && !(*key)[best]) {
        (*key)[best] = true;
        (*sample_of_scan)[best] = k;
      }
    }
}

// sample_data, ego_pose and the PCD files, one per scan.
void Writer::SampleData(const std::vector<std::size_t>& sample_of_scan,
                        const std::vector<bool>& key) {
  std::vector<std::size_t> prev(5, seq.scans.size()), next(seq.scans.size(), seq.scans.size());
  for (std::size_t i = 0; i < seq.scans.size(); ++i) {
    const int s = seq.scans[i].sensor;
    if (prev[s] < seq.scans.size()) next[prev[s]] = i;
    prev[s] = i;
  }
  std::fill(prev.begin(), prev.end(), seq.scans.size());
  for (std::size_t i = 0; i < seq.scans.size(); ++i) {
    const RecordedScan& s = seq.scans[i];
    const std::string ch = kNuScenesChannels[channel[s.sensor]];
    const std::int64_t ts = kEpochUs + s.timestamp_us;
    const std::string file = std::string(key[i] ? "samples/" : "sweeps/") + ch + "/" + scene +
                             "__" + ch + "__" + std::to_string(ts) + "_" + std::to_string(i) +
                             ".pcd";
    WritePcd(root / file, RadarCloud(seq, s, float64));
    const Position axle = s.ego_pose.position - a * UnitVector(s.ego_pose.yaw);
    const std::string token = Token("sample_data", i);
    tables["ego_pose"].push_back({{"token", token},
                                  {"timestamp", ts},
                                  {"translation", {axle.x(), axle.y(), 0.0}},
                                  {"rotation", Quaternion(s.ego_pose.yaw)},
                                  {"dualgrid_velocity", {s.ego_velocity.x(), s.ego_velocity.y()}},
                                  {"dualgrid_yaw_rate", {s.ego_yaw_rate}},
                                  {"dualgrid_lane_yaw", {s.lane_yaw}}});
    const std::size_t p = prev[s.sensor];
    tables["sample_data"].push_back(
        {{"token", token},
         {"sample_token", Token("sample", sample_of_scan[i])},
         {"ego_pose_token", token},
         {"calibrated_sensor_token", Token("calibrated_sensor", s.sensor)},
         {"timestamp", ts},
         {"fileformat", "pcd"},
         {"is_key_frame", static_cast<bool>(key[i])},
         {"height", 0},
         {"width", 0},
         {"filename", file},
         {"prev", p < seq.scans.size() ? Token("sample_data", p) : ""},
         {"next", next[i] < seq.scans.size() ? Token("sample_data", next[i]) : ""}});
    prev[s.sensor] = i;
  }
}

// instance, category and sample_annotation: every key frame's vehicles, linked per instance;
// num_radar_pts counts the points of the sample's key-frame scans in the box.
void Writer::Annotations(const std::vector<NuScenesKeyFrame>& keys,
                         const std::vector<std::size_t>& sample_of_scan,
                         const std::vector<bool>& key) {
  std::map<std::string, std::size_t> instance_of;  // vehicle id -> instance
  std::vector<std::vector<std::size_t>> anns;      // per instance: its annotations' rows
  std::map<std::string, std::string> categories;   // name -> token
  categories["vehicle.car"] = HexId("category/vehicle.car", 0);
  Json& rows = tables["sample_annotation"];
  for (std::size_t k = 0; k < keys.size(); ++k)
    for (const ReferenceObject& v : keys[k].vehicles) {
      const auto [it, added] = instance_of.try_emplace(v.id, anns.size());
      if (added) {
        anns.emplace_back();
        categories.try_emplace(v.type, HexId("category/" + v.type, 0));
        tables["instance"].push_back({{"token", Token("instance", it->second)},
                                      {"category_token", categories[v.type]},
                                      {"dualgrid_name", v.id}});
      }
      const BoxTest box(v.box);
      int points = 0;
      for (std::size_t i = 0; i < seq.scans.size(); ++i)
        if (key[i] && sample_of_scan[i] == k)
          for (std::size_t p = seq.scans[i].begin; p < seq.scans[i].end; ++p)
            points += box.Contains(seq.points[p].position) ? 1 : 0;
      const char* attribute = v.velocity.norm() > 0.5 ? "vehicle.moving" : "vehicle.stopped";
      anns[it->second].push_back(rows.size());
      rows.push_back({{"token", Token("sample_annotation", rows.size())},
                      {"sample_token", Token("sample", k)},
                      {"instance_token", Token("instance", it->second)},
                      {"visibility_token", "4"},
                      {"attribute_tokens", {HexId(std::string("attribute/") + attribute, 0)}},
                      {"translation", {v.box.center.x(), v.box.center.y(), 0.75}},
                      {"size", {v.box.width, v.box.length, 1.5}},
                      {"rotation", Quaternion(v.box.yaw)},
                      {"num_lidar_pts", 0},
                      {"num_radar_pts", points},
                      {"prev", ""},
                      {"next", ""}});
    }
  for (std::size_t n = 0; n < anns.size(); ++n) {
    const std::vector<std::size_t>& a = anns[n];
    for (std::size_t j = 0; j < a.size(); ++j) {
      if (j > 0) rows[a[j]]["prev"] = rows[a[j - 1]]["token"];
      if (j + 1 < a.size()) rows[a[j]]["next"] = rows[a[j + 1]]["token"];
    }
    Json& inst = tables["instance"][n];
    inst["nbr_annotations"] = a.size();
    inst["first_annotation_token"] = rows[a.front()]["token"];
    inst["last_annotation_token"] = rows[a.back()]["token"];
  }
  for (const auto& [name, token] : categories)
    tables["category"].push_back({{"token", token}, {"name", name}, {"description", name}});
}

}  // namespace

void WriteNuScenes(const RecordedSequence& seq, const std::vector<NuScenesKeyFrame>& keys,
                   const std::filesystem::path& root, const NuScenesWriteOptions& o) {
  if (keys.empty())
    throw std::invalid_argument(
        "export --format nuscenes: no key frame (the run is shorter "
        "than one 0.5 s sample)");
  // The rear axle 1 m ahead of the rear end.
  Writer w{seq,
           root,
           o.scene,
           o.float64,
           std::max(0.0, 0.5 * seq.ego_length - 1.0),
           Channels(seq.sensors),
           {}};
  const std::filesystem::path dir = root / o.version;
  for (const auto& d : {dir, root / "samples", root / "sweeps"})
    std::filesystem::create_directories(d);
  for (const char* ch : kNuScenesChannels) {
    std::filesystem::create_directories(root / "samples" / ch);
    std::filesystem::create_directories(root / "sweeps" / ch);
  }
  for (const char* t :
       {"attribute", "calibrated_sensor", "category", "ego_pose", "instance", "log", "map",
        "sample", "sample_annotation", "sample_data", "scene", "sensor", "visibility"})
    w.tables[t] = Json::array();
  w.Fixed(keys);
  std::vector<std::size_t> sample_of_scan;
  std::vector<bool> key;
  w.Samples(keys, &sample_of_scan, &key);
  w.SampleData(sample_of_scan, key);
  w.Annotations(keys, sample_of_scan, key);
  for (const auto& [name, rows] : w.tables) WriteJson(dir / (name + ".json"), rows, -1);
  Json ext = {
      {"generator", "dualgrid export"},
      {"ego",
       {{"length", seq.ego_length}, {"width", seq.ego_width}, {"rear_axle_to_centre", w.a}}}};
  for (std::size_t s = 0; s < 5; ++s)
    ext["sensors"].push_back({{"channel", kNuScenesChannels[w.channel[s]]},
                              {"name", seq.sensors[s].name},
                              {"fov", seq.sensors[s].fov},
                              {"min_range", seq.sensors[s].min_range},
                              {"max_range", seq.sensors[s].max_range}});
  if (o.scenario) {
    std::error_code ec;
    std::filesystem::copy_file(*o.scenario, dir / kTravellingScenario,
                               std::filesystem::copy_options::overwrite_existing, ec);
    if (ec) throw std::runtime_error((dir / kTravellingScenario).string() + ": " + ec.message());
    ext["scenario"] = kTravellingScenario;
  }
  WriteJson(dir / "dualgrid.json", ext);
}

}  // namespace dualgrid::recorded
