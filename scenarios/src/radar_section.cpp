#include <algorithm>

#include "fields.hpp"
#include "sections.hpp"

namespace dualgrid::scenario {
namespace detail {
namespace {

void ReadSensorFields(MapReader& r, radar::SensorParams* p, RadarConfig* radar) {
  if (auto m = r.Map("mount")) {
    radar->mounts_given.insert(p->name);
    m->Read("x", &p->mount.position.x());
    m->Read("y", &p->mount.position.y());
    m->ReadDegrees("yaw_deg", &p->mount.yaw);
    m->Finish();
  }
  ReadFields(r, kSensorDoubles, p);
  // The off-boresight profile (angles in degrees in the file).
  if (r.Has("off_boresight_deg")) {
    r.Read("off_boresight_deg", &p->off_boresight);
    for (double& a : p->off_boresight) a = DegToRad(a);
  }
  r.Read("off_boresight_resolution", &p->off_boresight_resolution);
  r.Read("off_boresight_accuracy", &p->off_boresight_accuracy);
}

// `sensors.multipath`: on / off (true / false), or a map of radar::MultipathParams fields, which
// turns it on (unless it says `enabled: false`). docs/radar.md, "Multipath".
void ReadMultipath(MapReader& section, radar::MultipathParams* mp) {
  if (!section.Has("multipath")) return;
  if (section.IsMap("multipath")) {
    auto r = section.Map("multipath");
    mp->enabled = true;
    r->Read("enabled", &mp->enabled);
    r->Read("rails", &mp->rails);
    r->Read("vehicles", &mp->vehicles);
    r->Read("rail_loss_db", &mp->rail_loss_db);
    r->Read("vehicle_loss_db", &mp->vehicle_loss_db);
    r->Read("vehicle_min_length", &mp->vehicle_min_length);
    r->Read("max_bounces", &mp->max_bounces);
    r->Read("min_pd", &mp->min_pd);
    r->Finish();
  } else {
    std::string text;
    section.Read("multipath", &text);
    // YAML 1.1's spellings of true and false, as yaml-cpp reads the other switches.
    const auto any_of = [&](std::initializer_list<const char*> words) {
      return std::any_of(words.begin(), words.end(), [&](const char* w) { return text == w; });
    };
    if (any_of({"on", "On", "ON", "true", "True", "TRUE", "yes", "Yes", "YES", "y", "Y"}))
      mp->enabled = true;
    else if (any_of({"off", "Off", "OFF", "false", "False", "FALSE", "no", "No", "NO", "n", "N"}))
      mp->enabled = false;
    else
      section.Fail("multipath",
                   "expected on, off or a map of its parameters (rail_loss_db, "
                   "vehicle_loss_db, ...), got '" +
                       text + "'");
  }
  std::string error;
  if (!mp->IsValid(&error)) Invalid(section.file(), "sensors.multipath", error);
}

}  // namespace

void ReadRadar(MapReader& root, const sim::ScenarioSpec& spec, RadarConfig* radar) {
  const auto& ego_type = spec.vehicle_types.at(spec.ego.type);
  auto section = root.Map("sensors");
  std::string accuracy = "datasheet";
  if (section) section->Read("accuracy", &accuracy);
  if (accuracy != "datasheet" && accuracy != "clean")
    section->Fail("accuracy", "expected 'datasheet' or 'clean', got '" + accuracy + "'");
  radar->accuracy = accuracy;
  radar->sensors = radar::DefaultRig(
      ego_type.length, ego_type.width,
      accuracy == "clean" ? radar::Accuracy::kClean : radar::Accuracy::kDataSheet);
  radar->rig_length = ego_type.length;
  radar->rig_width = ego_type.width;
  if (!section) return;
  std::string rig = "default";
  section->Read("rig", &rig);
  if (rig != "default") section->Fail("rig", "expected 'default', got '" + rig + "'");
  section->Read("noise", &radar->options.noise);
  section->Read("false_alarms", &radar->options.false_alarms);
  section->Read("occlusion", &radar->options.occlusion);
  ReadMultipath(*section, &radar->options.multipath);
  auto names = [&] {
    std::string all;
    for (const auto& s : radar->sensors) all += (all.empty() ? "" : ", ") + s.name;
    return all;
  };
  auto overrides = section->NamedMaps("overrides");
  // "all" first (every sensor), then the named sensors. (No reordering of the readers: assigning
  // a YAML::Node assigns the node it refers to.)
  for (auto& [name, r] : overrides) {
    if (name != "all") continue;
    for (auto& sensor : radar->sensors) ReadSensorFields(r, &sensor, radar);
    r.Finish();
  }
  for (auto& [name, r] : overrides) {
    if (name == "all") continue;
    const std::string& sensor = name;  // structured bindings cannot be captured before C++20
    auto it = std::find_if(radar->sensors.begin(), radar->sensors.end(),
                           [&](const radar::SensorParams& s) { return s.name == sensor; });
    if (it == radar->sensors.end())
      throw ConfigError(r.file() + ": key '" + r.path() + "' names unknown sensor '" + name +
                        "' (expected one of: " + names() + ")");
    ReadSensorFields(r, &*it, radar);
    r.Finish();
  }
  if (section->Has("use")) {
    std::vector<std::string> use;
    section->Read("use", &use);
    std::vector<radar::SensorParams> kept;
    for (const std::string& name : use) {
      auto it = std::find_if(radar->sensors.begin(), radar->sensors.end(),
                             [&](const radar::SensorParams& s) { return s.name == name; });
      if (it == radar->sensors.end())
        section->Fail("use",
                      "names unknown sensor '" + name + "' (expected one of: " + names() + ")");
      kept.push_back(*it);
    }
    if (kept.empty()) section->Fail("use", "must list at least one sensor");
    radar->sensors = kept;
  }
  section->Finish();
  for (const auto& s : radar->sensors) {
    std::string error;
    if (!s.IsValid(&error))
      Invalid(root.file(), "sensors.overrides." + s.name, error, DegreeAliases(kSensorDoubles));
  }
}

}  // namespace detail

bool PlaceRigOn(RadarConfig* radar, double length, double width) {
  if (length == radar->rig_length && width == radar->rig_width) return false;
  const std::vector<radar::SensorParams> rig = radar::DefaultRig(length, width);
  bool moved = false;
  for (radar::SensorParams& s : radar->sensors) {
    if (radar->mounts_given.count(s.name)) continue;
    for (const radar::SensorParams& d : rig) {
      if (d.name != s.name) continue;
      moved = moved || d.mount.position != s.mount.position || d.mount.yaw != s.mount.yaw;
      s.mount = d.mount;
    }
  }
  radar->rig_length = length;
  radar->rig_width = width;
  return moved;
}
}  // namespace dualgrid::scenario
