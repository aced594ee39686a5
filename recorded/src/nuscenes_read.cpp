// Reading one scene of a nuScenes-layout dataset (docs/recorded-data.md, "nuScenes").
#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>

#include "dualgrid/core/json_input.hpp"
#include "dualgrid/recorded/nuscenes.hpp"
#include "dualgrid/recorded/pcd.hpp"
#include "nuscenes_annotations.hpp"
#include "nuscenes_tables.hpp"

namespace dualgrid::recorded {

using nuscenes::Json;
using nuscenes::Table;
using nuscenes::Tables;

namespace {

int ChannelIndex(const std::string& channel) {
  for (int k = 0; k < 5; ++k)
    if (channel == kNuScenesChannels[k]) return k;
  return -1;
}

// What a dualgrid export adds in dualgrid.json (absent in the published data).
struct Extension {
  double length = kNuScenesEgoLength, width = kNuScenesEgoWidth;
  double rear_axle_to_centre = kNuScenesRearAxleToCentre;
  std::vector<std::string> order;       // channels in the sensors' order
  std::map<std::string, Json> sensors;  // channel -> {name, fov, min_range, max_range}
  std::optional<std::filesystem::path> scenario;
};

Extension ReadExtension(const std::filesystem::path& dir) {
  Extension e;
  const std::filesystem::path file = dir / "dualgrid.json";
  if (!InputExists(file)) return e;
  const Json j = ReadJsonInput(file, "nuScenes dualgrid extension");
  if (!j.is_object()) throw std::invalid_argument(file.string() + ": expected a JSON object");
  auto num = [&](const Json& o, const char* key, const std::string& where) {
    const auto it = o.find(key);
    if (it == o.end() || !it->is_number() || !std::isfinite(it->get<double>()))
      throw std::invalid_argument(file.string() + ": key '" + where + key +
                                  "': expected a finite number");
    return it->get<double>();
  };
  const Json ego = j.value("ego", Json::object());
  e.length = num(ego, "length", "ego.");
  e.width = num(ego, "width", "ego.");
  e.rear_axle_to_centre = num(ego, "rear_axle_to_centre", "ego.");
  if (const std::string error = EgoSizeError(e.length, e.width); !error.empty())
    throw std::invalid_argument(file.string() + ": key 'ego': " + error);
  for (const Json& s : j.value("sensors", Json::array())) {
    const auto c = s.find("channel");
    if (c == s.end() || !c->is_string() || ChannelIndex(c->get<std::string>()) < 0)
      throw std::invalid_argument(file.string() +
                                  ": key 'sensors[].channel': expected one of "
                                  "the five RADAR_ channels");
    for (const char* key : {"fov", "min_range", "max_range"}) num(s, key, "sensors[].");
    e.order.push_back(c->get<std::string>());
    e.sensors[c->get<std::string>()] = s;
  }
  if (const auto sc = j.find("scenario"); sc != j.end() && sc->is_string())
    e.scenario = dir / sc->get<std::string>();
  return e;
}

// A radar sample_data of the scene.
struct SampleData {
  std::string token, channel, filename, calibration, ego_pose;
  std::int64_t timestamp = 0;
  const Json* record = nullptr;
};

const Json& FindScene(Tables& tables, const std::string& scene) {
  const Table& t = tables.Get("scene");
  if (const auto it = t.index.find(scene); it != t.index.end()) return (*t.records)[it->second];
  std::string names;
  for (const Json& r : *t.records) {
    const std::string name = nuscenes::Str(t, r, "name");
    if (name == scene) return r;
    if (names.size() < 200) names += (names.empty() ? "" : ", ") + name;
  }
  throw std::invalid_argument(t.file.string() + ": field 'name': no scene named (or with token) '" +
                              scene + "' (scenes: " + names + ")");
}

// The scene's samples (token -> timestamp), following first_sample_token and next.
std::map<std::string, std::int64_t> SceneSamples(Tables& tables, const Json& scene) {
  const Table& st = tables.Get("scene");
  const Table& samples = tables.Get("sample");
  std::map<std::string, std::int64_t> out;
  std::string token = nuscenes::Str(st, scene, "first_sample_token");
  std::string from = nuscenes::Where(st, scene, "first_sample_token");
  while (!token.empty()) {
    const Json& r = tables.Record("sample", token, from);
    if (!out.emplace(token, nuscenes::Int(samples, r, "timestamp")).second)
      throw std::invalid_argument(nuscenes::Where(samples, r, "next") + "the samples loop");
    from = nuscenes::Where(samples, r, "next");
    token = nuscenes::Str(samples, r, "next");
  }
  return out;
}

std::vector<SampleData> RadarSampleData(Tables& tables,
                                        const std::map<std::string, std::int64_t>& samples) {
  const Table& sd = tables.Get("sample_data");
  const Table& cs = tables.Get("calibrated_sensor");
  const Table& sensors = tables.Get("sensor");
  std::map<std::string, std::string> channel_of;  // calibrated_sensor token -> radar channel
  std::vector<SampleData> out;
  for (const Json& r : *sd.records) {
    if (!samples.count(nuscenes::Str(sd, r, "sample_token"))) continue;
    SampleData s;
    s.calibration = nuscenes::Str(sd, r, "calibrated_sensor_token");
    auto ch = channel_of.find(s.calibration);
    if (ch == channel_of.end()) {
      const Json& c = tables.Record("calibrated_sensor", s.calibration,
                                    nuscenes::Where(sd, r, "calibrated_sensor_token"));
      const Json& sr = tables.Record("sensor", nuscenes::Str(cs, c, "sensor_token"),
                                     nuscenes::Where(cs, c, "sensor_token"));
      const std::string channel = nuscenes::Str(sensors, sr, "channel");
      const bool radar = nuscenes::Str(sensors, sr, "modality") == "radar";
      if (radar && ChannelIndex(channel) < 0)
        throw std::invalid_argument(nuscenes::Where(sensors, sr, "channel") +
                                    "unknown radar channel '" + channel +
                                    "' (RADAR_FRONT, RADAR_FRONT_LEFT, "
                                    "RADAR_FRONT_RIGHT, RADAR_BACK_LEFT, RADAR_BACK_RIGHT)");
      ch = channel_of.emplace(s.calibration, radar ? channel : std::string()).first;
    }
    if (ch->second.empty()) continue;  // a camera or lidar
    s.token = r["token"].get<std::string>();
    s.channel = ch->second;
    s.filename = nuscenes::Str(sd, r, "filename");
    s.ego_pose = nuscenes::Str(sd, r, "ego_pose_token");
    s.timestamp = nuscenes::Int(sd, r, "timestamp");
    s.record = &r;
    out.push_back(s);
  }
  return out;
}

radar::SensorParams Mount(Tables& tables, const SampleData& s, const Extension& ext) {
  const Table& cs = tables.Get("calibrated_sensor");
  const Json& c = tables.Record("calibrated_sensor", s.calibration, "");
  const std::vector<double> t = nuscenes::Numbers(cs, c, "translation", 3);
  radar::SensorParams p;
  p.name = s.channel;
  p.mount = {{t[0] - ext.rear_axle_to_centre, t[1]},
             nuscenes::QuaternionYaw(nuscenes::Numbers(cs, c, "rotation", 4))};
  // The ARS408 as we read its data sheet: +-60 deg near range; dualgrid.json overrides.
  p.fov = DegToRad(120.0);
  p.min_range = 0.2;
  p.max_range = 100.0;
  if (const auto it = ext.sensors.find(s.channel); it != ext.sensors.end()) {
    p.name = it->second.value("name", s.channel);
    p.fov = it->second["fov"].get<double>();
    p.min_range = it->second["min_range"].get<double>();
    p.max_range = it->second["max_range"].get<double>();
  }
  std::string error;
  if (!p.IsValid(&error))
    throw std::invalid_argument(cs.file.string() + ": record '" + s.calibration + "': " + error);
  return p;
}

// The ego's state per sample_data: its box centre and heading from the ego_pose (the rear
// axle's), its velocity and yaw rate from dualgrid's keys of the record, else from the poses
// around it (docs/recorded-data.md, "The ego's velocity").
void EgoStates(Tables& tables, const std::vector<SampleData>& sds, const Extension& ext,
               std::vector<RecordedScan>* scans, bool* estimated) {
  const Table& ep = tables.Get("ego_pose");
  std::vector<Position> axle(sds.size());
  std::vector<const Json*> rec(sds.size());
  for (std::size_t i = 0; i < sds.size(); ++i) {
    const Json& r =
        tables.Record("ego_pose", sds[i].ego_pose,
                      nuscenes::Where(tables.Get("sample_data"), *sds[i].record, "ego_pose_token"));
    rec[i] = &r;
    const std::vector<double> t = nuscenes::Numbers(ep, r, "translation", 3);
    const double yaw = nuscenes::QuaternionYaw(nuscenes::Numbers(ep, r, "rotation", 4));
    axle[i] = {t[0], t[1]};
    (*scans)[i].ego_pose = {axle[i] + ext.rear_axle_to_centre * UnitVector(yaw), yaw};
    (*scans)[i].lane_yaw = yaw;
  }
  *estimated = false;
  for (std::size_t i = 0; i < sds.size(); ++i) {
    const Json& r = *rec[i];
    RecordedScan& s = (*scans)[i];
    if (r.contains("dualgrid_velocity")) {
      const std::vector<double> v = nuscenes::Numbers(ep, r, "dualgrid_velocity", 2);
      s.ego_velocity = {v[0], v[1]};
      s.ego_yaw_rate = nuscenes::Numbers(ep, r, "dualgrid_yaw_rate", 1)[0];
      s.lane_yaw = nuscenes::Numbers(ep, r, "dualgrid_lane_yaw", 1)[0];
      continue;
    }
    *estimated = true;
    // The nearest poses at least 50 ms before and after (one-sided at the ends).
    std::size_t a = i, b = i;
    while (a > 0 && sds[i].timestamp - sds[a].timestamp < 50000) --a;
    while (b + 1 < sds.size() && sds[b].timestamp - sds[i].timestamp < 50000) ++b;
    const double dt = static_cast<double>(sds[b].timestamp - sds[a].timestamp) / 1e6;
    if (!(dt > 0.0)) continue;  // a single pose: at rest
    const double yaw_a = (*scans)[a].ego_pose.yaw, yaw_b = (*scans)[b].ego_pose.yaw;
    s.ego_yaw_rate = WrapAngle(yaw_b - yaw_a) / dt;
    const Velocity v_axle = (axle[b] - axle[a]) / dt;
    s.ego_velocity =
        v_axle + s.ego_yaw_rate * ext.rear_axle_to_centre * UnitVector(s.ego_pose.yaw + 0.5 * kPi);
  }
}

bool Keep(const std::vector<int>& states, double v) {
  return states.empty() ||
         std::find(states.begin(), states.end(), static_cast<int>(v)) != states.end();
}

// The points of one sample_data's PCD file, moved to the world frame; counts what the filters
// removed. `sensor`: the sequence's index of its channel.
void ReadPoints(const std::filesystem::path& root, Tables& tables, const SampleData& s,
                const NuScenesOptions& o, NuScenesScene* out, RecordedScan* scan) {
  const std::filesystem::path file = root / s.filename;
  const PcdCloud cloud = ReadPcd(file);
  auto column = [&](const char* name, bool needed) -> const std::vector<double>* {
    const std::vector<double>* c = cloud.Column(name);
    if (!c && needed)
      throw std::invalid_argument(file.string() + ": header key 'FIELDS': field '" + name +
                                  "' is missing");
    return c;
  };
  const auto* x = column("x", true);
  const auto* y = column("y", true);
  const auto* z = column("z", false);
  const auto* vx = column("vx", true);
  const auto* vy = column("vy", true);
  const auto* vxc = column("vx_comp", true);
  const auto* vyc = column("vy_comp", true);
  const auto* rcs = column("rcs", false);
  const auto* inv = column("invalid_state", !o.invalid_states.empty());
  const auto* dyn = column("dyn_prop", !o.dynprop_states.empty());
  const auto* amb = column("ambig_state", !o.ambig_states.empty());
  const Table& cs = tables.Get("calibrated_sensor");
  const Json& c = tables.Record("calibrated_sensor", s.calibration, "");
  const std::vector<double> ct = nuscenes::Numbers(cs, c, "translation", 3);
  const std::vector<double> cq = nuscenes::Numbers(cs, c, "rotation", 4);
  const Table& ep = tables.Get("ego_pose");
  const Json& e = tables.Record("ego_pose", s.ego_pose, "");
  const std::vector<double> et = nuscenes::Numbers(ep, e, "translation", 3);
  const std::vector<double> eq = nuscenes::Numbers(ep, e, "rotation", 4);
  scan->begin = out->sequence.points.size();
  const std::size_t n = cloud.size();
  // The devkit: a NaN in the first point marks an empty cloud.
  const bool empty = n > 0 && std::any_of(cloud.columns.begin(), cloud.columns.end(),
                                          [](const auto& col) { return std::isnan(col[0]); });
  if (empty) ++out->empty_clouds;
  for (std::size_t i = 0; i < n && !empty; ++i) {
    for (const auto& [name, col] :
         {std::pair{"x", x}, {"y", y}, {"vx", vx}, {"vy", vy}, {"vx_comp", vxc}, {"vy_comp", vyc}})
      if (!std::isfinite((*col)[i]))
        throw std::invalid_argument(file.string() + ": field '" + name + "': not finite at point " +
                                    std::to_string(i));
    if ((inv && !Keep(o.invalid_states, (*inv)[i])) ||
        (dyn && !Keep(o.dynprop_states, (*dyn)[i])) || (amb && !Keep(o.ambig_states, (*amb)[i]))) {
      ++out->filtered_points;
      continue;
    }
    const double px = (*x)[i], py = (*y)[i], pz = z && std::isfinite((*z)[i]) ? (*z)[i] : 0.0;
    const double range = std::hypot(px, py);
    if (!(range > 0.0)) {
      ++out->filtered_points;  // at the sensor: no line of sight
      continue;
    }
    std::vector<double> q = nuscenes::Rotate(cq, {px, py, pz});
    q = nuscenes::Rotate(eq, {q[0] + ct[0], q[1] + ct[1], q[2] + ct[2]});
    RecordedPoint p;
    p.range = range;
    p.azimuth = std::atan2(py, px);
    // vx_comp, vy_comp: the ego-motion-compensated radial velocity as a vector in the sensor
    // frame; vx, vy the velocity relative to the radar. Each along the line of sight.
    p.radial_speed = ((*vxc)[i] * px + (*vyc)[i] * py) / range;
    p.range_rate = ((*vx)[i] * px + (*vy)[i] * py) / range;
    p.rcs = rcs && std::isfinite((*rcs)[i]) ? (*rcs)[i] : 0.0;
    p.position = {q[0] + et[0], q[1] + et[1]};
    out->sequence.points.push_back(p);
  }
  scan->end = out->sequence.points.size();
}

// The references of every scan (moving instances interpolated to its time, sorted by token) and
// the labels of its points (the moving box they fall in, else static).
void Label(const nuscenes::SceneInstances& inst, double margin, NuScenesScene* out) {
  RecordedSequence& seq = out->sequence;
  seq.annotated = true;
  seq.has_labels = true;
  std::vector<int> track_of(inst.instances.size(), -1);
  for (std::size_t k = 0; k < inst.instances.size(); ++k)
    if (inst.instances[k].moving) {
      track_of[k] = static_cast<int>(seq.track_names.size());
      seq.track_names.push_back(inst.instances[k].token);
    }
  for (RecordedScan& s : seq.scans) {
    s.ref_begin = seq.references.size();
    for (std::size_t i = s.begin; i < s.end; ++i) seq.points[i].label = kStaticLabel;
    for (std::size_t k = 0; k < inst.instances.size(); ++k) {
      const auto box = nuscenes::Interpolate(inst.instances[k], s.timestamp_us);
      if (!box || track_of[k] < 0) continue;
      OrientedBox grown = box->box;
      grown.length += 2.0 * margin;
      grown.width += 2.0 * margin;
      const BoxTest test(grown);
      for (std::size_t i = s.begin; i < s.end; ++i)
        if (test.Contains(seq.points[i].position)) {
          seq.points[i].label = inst.instances[k].label;
          seq.points[i].track = track_of[k];
        }
      seq.references.push_back(*box);
    }
    s.ref_end = seq.references.size();
  }
  for (const auto& in : inst.instances) {
    (in.moving ? out->moving_instances : out->static_instances) += 1;
    out->annotations.insert(out->annotations.end(), in.keys.begin(), in.keys.end());
  }
  std::stable_sort(out->annotations.begin(), out->annotations.end(),
                   [](const auto& a, const auto& b) { return a.timestamp_us < b.timestamp_us; });
}

}  // namespace

void NuScenesOptions::Validate() const {
  if (scene.empty()) throw std::invalid_argument("--scene: the scene's name or token is needed");
  if (version.empty() || version.find('/') != std::string::npos)
    throw std::invalid_argument("--version: a version folder name (v1.0-mini, v1.0-trainval, ...)");
  if (!(moving_speed >= 0.0)) throw std::invalid_argument("moving_speed: must be >= 0");
  if (!(label_margin >= 0.0)) throw std::invalid_argument("label_margin: must be >= 0");
  if (min_annotations < 1) throw std::invalid_argument("min_annotations: must be >= 1");
}

// ReadNuScenes without the guard that names the folder for out-of-memory and type errors.
static NuScenesScene ReadScene(const std::filesystem::path& root, const NuScenesOptions& o) {
  o.Validate();
  const std::filesystem::path dir = root / o.version;
  if (!InputExists(dir))
    throw std::invalid_argument(dir.string() + ": missing: no version folder '" + o.version +
                                "' (--version)");
  CheckInputFolder(dir, "nuScenes version folder");
  Tables tables(dir);
  const Extension ext = ReadExtension(dir);
  NuScenesScene out;
  const Json& scene = FindScene(tables, o.scene);
  const Table& st = tables.Get("scene");
  out.scene_token = scene["token"].get<std::string>();
  out.sequence.name = nuscenes::Str(st, scene, "name");
  const std::map<std::string, std::int64_t> samples = SceneSamples(tables, scene);
  std::vector<SampleData> sds = RadarSampleData(tables, samples);
  if (sds.empty())
    throw std::invalid_argument(tables.Get("sample_data").file.string() +
                                ": field 'sample_token': no radar sample_data in scene '" +
                                out.sequence.name + "'");
  // The sensors: dualgrid.json's order, else the channels' in kNuScenesChannels order.
  std::vector<std::string> order = ext.order;
  if (order.empty())
    for (const char* c : kNuScenesChannels)
      if (std::any_of(sds.begin(), sds.end(), [&](const auto& s) { return s.channel == c; }))
        order.push_back(c);
  std::map<std::string, int> sensor_of;
  for (const SampleData& s : sds) {
    const auto it = std::find(order.begin(), order.end(), s.channel);
    if (it == order.end())
      throw std::invalid_argument(dir.string() + "/dualgrid.json: key 'sensors': channel " +
                                  s.channel + " is not listed");
    sensor_of[s.channel] = static_cast<int>(it - order.begin());
  }
  std::stable_sort(sds.begin(), sds.end(), [&](const SampleData& a, const SampleData& b) {
    return a.timestamp != b.timestamp ? a.timestamp < b.timestamp
                                      : sensor_of[a.channel] < sensor_of[b.channel];
  });
  out.sequence.sensors.resize(order.size());
  std::set<std::string> mounted;
  for (const SampleData& s : sds)
    if (mounted.insert(s.channel).second)
      out.sequence.sensors[sensor_of[s.channel]] = Mount(tables, s, ext);
  out.channels = order;
  out.sequence.ego_length = ext.length;
  out.sequence.ego_width = ext.width;
  out.sequence.scans.resize(sds.size());
  EgoStates(tables, sds, ext, &out.sequence.scans, &out.ego_velocity_estimated);
  for (std::size_t i = 0; i < sds.size(); ++i) {
    RecordedScan& scan = out.sequence.scans[i];
    scan.timestamp_us = sds[i].timestamp;
    scan.sensor = sensor_of[sds[i].channel];
    ReadPoints(root, tables, sds[i], o, &out, &scan);
  }
  out.sample_data = sds.size();
  const nuscenes::SceneInstances inst = nuscenes::ReadInstances(tables, samples, o);
  out.skipped_instances = inst.skipped;
  Label(inst, o.label_margin, &out);
  const std::int64_t t0 = out.sequence.scans.front().timestamp_us;
  out.sequence.time_origin_us = t0 - t0 % 1000000;
  out.scenario = ext.scenario;
  return out;
}

std::string CategoryOfLabel(int label) {
  switch (label) {
    case 0:
      return "vehicle.car";
    case 1:
      return "vehicle.construction";
    case 2:
      return "vehicle.truck";
    case 3:
    case 4:
      return "vehicle.bus.rigid";
    case 5:
      return "vehicle.bicycle";
    case 6:
      return "vehicle.motorcycle";
    case 7:
      return "human.pedestrian.adult";
    default:
      return "movable_object.debris";
  }
}

int LabelOfCategory(const std::string& c) {
  if (c == "vehicle.car" || c.rfind("vehicle.emergency.", 0) == 0) return 0;
  if (c == "vehicle.construction") return 1;
  if (c == "vehicle.truck" || c == "vehicle.trailer") return 2;
  if (c.rfind("vehicle.bus", 0) == 0) return 3;
  if (c == "vehicle.bicycle") return 5;
  if (c == "vehicle.motorcycle") return 6;
  if (c.rfind("vehicle.", 0) == 0) return 10;
  return -1;
}

NuScenesScene ReadNuScenes(const std::filesystem::path& root, const NuScenesOptions& o) {
  return ReadingJsonInput(root, "nuScenes data set", [&] { return ReadScene(root, o); });
}

}  // namespace dualgrid::recorded
