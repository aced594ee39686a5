#include "dualgrid/scenario/loader.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <type_traits>

#include "dualgrid/core/input_file.hpp"
#include "dualgrid/core/validation.hpp"
#include "dualgrid/sim/sumo_files.hpp"
#include "dualgrid/sim/sumo_simulation.hpp"
#include "yaml_reader.hpp"

namespace dualgrid::scenario {
namespace {

void ReadVehicle(MapReader& r, sim::VehicleSpec* v) {
  r.Read("id", &v->id);
  r.Read("type", &v->type);
  r.Read("route", &v->route);
  r.Read("depart", &v->depart);
  r.Read("lane", &v->lane);
  r.Read("position", &v->position);
  r.Read("speed", &v->speed);
  r.Read("desired_speed", &v->desired_speed);
  r.Read("lane_change", &v->lane_change);
}

std::string Shown(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

void ReadSim(MapReader& root, sim::ScenarioSpec* s) {
  root.Read("name", &s->name);
  root.Read("description", &s->description);
  const std::filesystem::path here = std::filesystem::path(root.file()).parent_path();
  const auto relative_to_file = [&](const std::string& p) {
    return std::filesystem::absolute(here / p).lexically_normal().string();
  };
  // SUMO's own configuration: its network and route files (docs/scenarios.md).
  std::optional<double> cfg_step;
  if (root.Has("sumo_config")) {
    if (root.Has("network"))
      root.Fail("network", "must not be given with sumo_config (whose net-file is the network)");
    std::string cfg;
    root.Read("sumo_config", &cfg);
    try {
      const sim::SumoConfigInputs in = sim::ReadSumoConfig(relative_to_file(cfg));
      s->network = in.net_file.string();
      for (const auto& f : in.route_files) s->route_files.push_back(f.string());
      for (const auto& f : in.additional_files) s->additional_files.push_back(f.string());
      cfg_step = in.step_length;
    } catch (const std::invalid_argument& e) {
      root.Fail("sumo_config", e.what());
    }
  } else {
    root.Require("network", &s->network);
  }
  // A network given as a file (ending in .xml) is read relative to the scenario file, so a
  // scenario and its network can move together; a bare name is one of the built networks.
  if (const std::filesystem::path net(s->network);
      sim::IsNetworkPath(s->network) && net.is_relative())
    s->network = relative_to_file(s->network);
  root.Read("duration", &s->duration);
  root.Read("step_length", &s->step_length);
  if (cfg_step && *cfg_step != s->step_length)
    s->warnings.push_back(root.file() + ": key 'sumo_config': its step-length " + Shown(*cfg_step) +
                          " s is replaced by step_length " + Shown(s->step_length) +
                          " s (the radar cycle)");
  root.Read("seed", &s->seed);
  root.Read("lane_change_duration", &s->lane_change_duration);

  for (auto& [name, r] : root.NamedMaps("vehicle_types")) {
    sim::VehicleTypeSpec t;
    r.Read("length", &t.length);
    r.Read("width", &t.width);
    r.Read("max_speed", &t.max_speed);
    r.Read("accel", &t.accel);
    r.Read("decel", &t.decel);
    r.Read("rcs_dbsm", &t.rcs_dbsm);
    r.Read("vclass", &t.vclass);
    r.Read("overtake_right", &t.overtake_right);
    r.Finish();
    s->vehicle_types[name] = t;
  }
  if (s->vehicle_types.empty()) s->vehicle_types["car"] = {};

  if (auto routes = root.Map("routes")) {
    // Each route is a list of edge ids under its name.
    for (const std::string& name : routes->Keys()) routes->Read(name, &s->routes[name]);
    routes->Finish();
  }

  auto ego = root.Map("ego");
  if (!ego) root.Fail("ego", "is required");
  s->ego.id = "ego";
  s->ego.lane_change = false;  // the ego keeps its lane unless the scenario says otherwise
  if (ego->Has("from_routes")) {
    // A vehicle of the route files is the ego: SUMO places and drives it.
    for (const char* key : {"id", "type", "route", "depart", "lane", "position", "speed"})
      if (ego->Has(key))
        ego->Fail(key, "must not be given with from_routes (the route file defines the ego)");
    ego->Read("from_routes", &s->ego.id);
    s->ego_from_routes = true;
    s->ego_speed.mode = sim::SpeedPolicy::Mode::kSumo;
  }
  ReadVehicle(*ego, &s->ego);
  if (s->ego.desired_speed)
    ego->Fail("desired_speed", "is not used for the ego: set ego.speed_policy.speed");
  if (auto sp = ego->Map("speed_policy")) {
    s->ego_speed.mode = sim::SpeedPolicy::Mode::kCruise;
    std::string mode = "cruise";
    sp->Read("mode", &mode);
    if (mode == "cruise")
      s->ego_speed.mode = sim::SpeedPolicy::Mode::kCruise;
    else if (mode == "fixed")
      s->ego_speed.mode = sim::SpeedPolicy::Mode::kFixed;
    else
      sp->Fail("mode", "expected 'cruise' or 'fixed', got '" + mode + "'");
    sp->Read("speed", &s->ego_speed.speed);
    sp->Finish();
  } else {
    s->ego_speed.speed = s->ego.speed;
  }
  ego->Finish();

  if (auto traffic = root.Map("traffic")) {
    std::vector<std::string> files;
    traffic->Read("route_files", &files);
    for (const std::string& f : files) s->route_files.push_back(relative_to_file(f));
    files.clear();
    traffic->Read("additional_files", &files);
    for (const std::string& f : files) s->additional_files.push_back(relative_to_file(f));
    if (auto rcs = traffic->Map("rcs_dbsm")) {
      for (const std::string& type : rcs->Keys()) {
        double v = 0.0;
        rcs->Read(type, &v);
        s->type_rcs[type] = v;
      }
      rcs->Finish();
    }
    for (auto& r : traffic->MapList("vehicles")) {
      sim::VehicleSpec v;
      ReadVehicle(r, &v);
      r.Finish();
      s->vehicles.push_back(v);
    }
    for (auto& r : traffic->MapList("flows")) {
      sim::FlowSpec f;
      r.Read("id", &f.id);
      r.Read("type", &f.type);
      r.Read("route", &f.route);
      r.Read("begin", &f.begin);
      r.Read("end", &f.end);
      r.Read("period", &f.period);
      r.Read("lane", &f.lane);
      r.Read("position", &f.position);
      r.Read("speed_min", &f.speed_min);
      r.Read("speed_max", &f.speed_max);
      r.Finish();
      s->flows.push_back(f);
    }
    traffic->Finish();
  }

  for (auto& r : root.MapList("actions")) {
    sim::ActionSpec a;
    r.Read("time", &a.time);
    r.Read("vehicle", &a.vehicle);
    r.Read("set_speed", &a.set_speed);
    r.Read("change_lane", &a.change_lane);
    r.Read("duration", &a.duration);
    r.Finish();
    s->actions.push_back(a);
  }

  if (auto obstacles = root.Map("obstacles")) {
    for (auto& r : obstacles->MapList("guard_rails")) {
      sim::GuardRail g;
      r.Read("id", &g.id);
      r.Read("points", &g.points);
      r.Read("rcs_dbsm_per_metre", &g.rcs_dbsm_per_metre);
      r.Finish();
      if (g.id.empty()) g.id = "rail_" + std::to_string(s->guard_rails.size());
      s->guard_rails.push_back(g);
    }
    for (auto& r : obstacles->MapList("parked")) {
      sim::ParkedBox p;
      r.Read("id", &p.id);
      r.Read("center", &p.box.center);
      r.Read("yaw", &p.box.yaw);
      r.Read("length", &p.box.length);
      r.Read("width", &p.box.width);
      r.Read("rcs_dbsm", &p.rcs_dbsm);
      r.Finish();
      if (p.id.empty()) p.id = "parked_" + std::to_string(s->parked.size());
      s->parked.push_back(p);
    }
    obstacles->Finish();
  }
}

// One table per parameter struct: the YAML key, the member, and whether the file gives it in
// degrees. The loader reads and ConfigToJson writes through the same tables, so a new parameter
// is one line here.
template <typename S, typename T>
struct Field {
  const char* key;
  T S::*member;
  bool degrees = false;
};
using FP = filter::FilterParams;
using SP = radar::SensorParams;
const Field<FP, double> kFilterDoubles[] = {
    {"length_x", &FP::length_x},
    {"width_y", &FP::width_y},
    {"resolution", &FP::resolution},
    {"process_noise_position", &FP::process_noise_position},
    {"process_noise_velocity", &FP::process_noise_velocity},
    {"persistence", &FP::persistence},
    {"birth_probability", &FP::birth_probability},
    {"birth_max_tangential_speed", &FP::birth_max_tangential_speed},
    {"birth_sigma_radial", &FP::birth_sigma_radial},
    {"doppler_fit_radius", &FP::doppler_fit_radius},
    {"doppler_fit_sigma", &FP::doppler_fit_sigma},
    {"birth_fit_uniform_share", &FP::birth_fit_uniform_share},
    {"max_speed", &FP::max_speed},
    {"sigma_f", &FP::sigma_f},
    {"sigma_static_distance", &FP::sigma_static_distance},
    {"sigma_static_velocity", &FP::sigma_static_velocity},
    {"sigma_v", &FP::sigma_v},
    {"cutoff_sigmas", &FP::cutoff_sigmas},
    {"occupied_mass", &FP::occupied_mass},
    {"free_mass", &FP::free_mass},
    {"free_mass_no_return", &FP::free_mass_no_return},
    {"free_angle_bin_deg", &FP::free_angle_bin, true},
    {"free_decay", &FP::free_decay},
    {"static_persistence", &FP::static_persistence},
    {"static_gain", &FP::static_gain},
    {"static_speed", &FP::static_speed},
    {"decay_eps", &FP::decay_eps},
};
const Field<FP, int> kFilterInts[] = {
    {"num_particles", &FP::num_particles},
    {"num_birth", &FP::num_birth},
    {"free_bin_dilation", &FP::free_bin_dilation},
};
const Field<SP, double> kSensorDoubles[] = {
    {"fov_deg", &SP::fov, true},
    {"min_range", &SP::min_range},
    {"max_range", &SP::max_range},
    {"min_range_rate", &SP::min_range_rate},
    {"max_range_rate", &SP::max_range_rate},
    {"range_resolution", &SP::range_resolution},
    {"azimuth_resolution_deg", &SP::azimuth_resolution, true},
    {"range_rate_resolution", &SP::range_rate_resolution},
    {"range_accuracy", &SP::range_accuracy},
    {"azimuth_accuracy_deg", &SP::azimuth_accuracy, true},
    {"range_rate_accuracy", &SP::range_rate_accuracy},
    {"reference_range", &SP::reference_range},
    {"reference_rcs_dbsm", &SP::reference_rcs_dbsm},
    {"reference_pd", &SP::reference_pd},
    {"false_alarm_rate", &SP::false_alarm_rate},
    {"update_period", &SP::update_period},
};

template <typename S, typename T, std::size_t N>
void ReadFields(MapReader& r, const Field<S, T> (&fields)[N], S* out) {
  for (const auto& f : fields) {
    if constexpr (std::is_same_v<T, double>) {
      if (f.degrees) {
        r.ReadDegrees(f.key, &(out->*f.member));
        continue;
      }
    }
    r.Read(f.key, &(out->*f.member));
  }
}

template <typename S, typename T, std::size_t N>
void WriteFields(const Field<S, T> (&fields)[N], const S& in, nlohmann::json* j) {
  for (const auto& f : fields) {
    if constexpr (std::is_same_v<T, double>) {
      (*j)[f.key] = f.degrees ? RadToDeg(in.*f.member) : in.*f.member;
    } else {
      (*j)[f.key] = in.*f.member;
    }
  }
}

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

void WriteSensorProfile(const radar::SensorParams& s, nlohmann::json* j) {
  std::vector<double> deg;
  for (double a : s.off_boresight) deg.push_back(RadToDeg(a));
  (*j)["off_boresight_deg"] = deg;
  (*j)["off_boresight_resolution"] = s.off_boresight_resolution;
  (*j)["off_boresight_accuracy"] = s.off_boresight_accuracy;
}

// Turns an IsValid message into a ConfigError naming the key under `section`. FieldCheck
// messages, "field = value: expected what", read as the parser's own: "key '<section>.field'
// expected what, got value"; other validators write "field: message" or "field message".
[[noreturn]] void Invalid(const std::string& file, const std::string& section,
                          const std::string& error) {
  const auto key = [&](const std::string& field) {
    return file + ": key '" + (section.empty() ? field : section + "." + field) + "' ";
  };
  auto colon = error.find(": ");
  const auto equals = error.find(" = ");
  if (equals != std::string::npos && equals < colon) {
    const auto expected = error.find(": expected ", equals);
    if (expected != std::string::npos)
      throw ConfigError(key(error.substr(0, equals)) + "expected " + error.substr(expected + 11) +
                        ", got " + error.substr(equals + 3, expected - equals - 3));
  }
  std::size_t skip = 2;
  if (colon == std::string::npos) colon = error.find(' '), skip = 1;
  const std::string field = colon == std::string::npos ? error : error.substr(0, colon);
  const std::string message =
      colon == std::string::npos ? "is invalid" : error.substr(colon + skip);
  throw ConfigError(key(field) + message);
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
    if (!s.IsValid(&error)) Invalid(root.file(), "sensors.overrides." + s.name, error);
  }
}

}  // namespace

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

namespace {

// Reads a switch given by name into *out, naming the accepted values on error.
template <typename E>
void ReadSwitch(MapReader& r, const std::string& key, std::optional<E> (*parse)(std::string_view),
                const char* accepted, E* out) {
  if (!r.Has(key)) return;
  std::string name;
  r.Read(key, &name);
  const std::optional<E> v = parse(name);
  if (!v) r.Fail(key, std::string("expected ") + accepted + ", got '" + name + "'");
  *out = *v;
}

void ReadGridPlacement(MapReader& r, const filter::FilterParams& f, GridPlacement* g) {
  if (r.Has("frame")) {
    std::string frame;
    r.Read("frame", &frame);
    if (frame == "world")
      g->frame = GridPlacement::Frame::kWorld;
    else if (frame == "heading")
      g->frame = GridPlacement::Frame::kHeading;
    else if (frame == "follow")
      g->frame = GridPlacement::Frame::kFollow;
    else
      r.Fail("frame", "expected 'follow', 'heading' or 'world', got '" + frame + "'");
  }
  if (r.Has("realign_deg")) {
    if (g->frame != GridPlacement::Frame::kFollow)
      r.Fail("realign_deg", "is used only with frame: follow (the grid that turns with the road)");
    r.Read("realign_deg", &g->realign_deg);
    if (!(g->realign_deg > 0.0 && g->realign_deg <= 90.0))
      r.Fail("realign_deg", "expected an angle in (0, 90] deg, got " + Shown(g->realign_deg));
  }
  auto read_edge = [&](const char* key, double extent, const char* extent_key, double* out) {
    if (!r.Has(key)) return;
    r.Read(key, out);
    if (!(std::isfinite(*out) && *out >= 0.0 && *out <= extent)) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "expected a distance in [0, %s = %g] m, got %g", extent_key,
                    extent, *out);
      r.Fail(key, buf);
    }
  };
  read_edge("ahead", f.length_x, "length_x", &g->ahead);
  read_edge("left", f.width_y, "width_y", &g->left);
}

void ReadFilter(MapReader& root, ScenarioConfig* config) {
  filter::FilterParams* f = &config->filter;
  auto r = root.Map("filter");
  if (!r) return;
  // A preset first: the keys below override it.
  if (r->Has("preset")) {
    r->Read("preset", &config->filter_preset);
    const std::optional<filter::FilterParams> preset = filter::Preset(config->filter_preset);
    if (!preset)
      r->Fail("preset", "expected one of " + std::string(filter::PresetNames()) + ", got '" +
                            config->filter_preset + "'");
    *f = *preset;
  }
  ReadFields(*r, kFilterDoubles, f);
  ReadFields(*r, kFilterInts, f);
  std::string mode(filter::ToString(f->mode));
  r->Read("mode", &mode);
  const auto parsed = filter::ParseWeightMode(mode);
  if (!parsed) r->Fail("mode", "expected 'position', 'velocity' or 'dual', got '" + mode + "'");
  f->mode = *parsed;
  ReadSwitch(*r, "zero_likelihood", filter::ParseZeroLikelihood, "'keep_prediction' or 'literal'",
             &f->zero_likelihood);
  ReadSwitch(*r, "velocity_likelihood", filter::ParseVelocityLikelihood,
             "'vector', 'radial' or 'radial_fit'", &f->velocity_likelihood);
  ReadSwitch(*r, "normalisation", filter::ParseNormalisation, "'per_cell' or 'literal'",
             &f->normalisation);
  constexpr const char* kBirthNames = "'doppler', 'uniform' or 'doppler_fit'";
  if (r->IsMap("birth_velocity")) {
    // Per mode: {position: uniform, velocity: doppler, dual: doppler}.
    auto per_mode = r->Map("birth_velocity");
    for (filter::WeightMode m : {filter::WeightMode::kPosition, filter::WeightMode::kVelocity,
                                 filter::WeightMode::kDual}) {
      filter::BirthVelocity v = f->birth_velocity;
      const std::string key(filter::ToString(m));
      if (!per_mode->Has(key)) continue;
      ReadSwitch(*per_mode, key, filter::ParseBirthVelocity, kBirthNames, &v);
      config->birth_velocity_by_mode[m] = v;
    }
    per_mode->Finish();
  } else {
    ReadSwitch(*r, "birth_velocity", filter::ParseBirthVelocity, kBirthNames, &f->birth_velocity);
  }
  ReadGridPlacement(*r, *f, &config->grid);  // after length_x / width_y: it checks against them
  r->Finish();
  std::string error;
  if (!f->IsValid(&error)) Invalid(root.file(), "filter", error);
}

void ReadEvaluation(MapReader& root, EvaluationConfig* e) {
  auto r = root.Map("evaluation");
  if (!r) return;
  r->Read("dynamic_threshold", &e->dynamic_threshold);
  r->Read("dbscan_eps", &e->dbscan.eps);
  r->Read("dbscan_min_points", &e->dbscan.min_points);
  r->Read("min_cluster_mass", &e->min_cluster_mass);
  r->Read("gate_box_margin", &e->tracking.association.box_margin);
  r->Read("gate_center", &e->tracking.association.center_gate);
  r->Read("consistent_required", &e->tracking.required);
  r->Read("consistent_window", &e->tracking.window);
  r->Read("min_frames_in_grid", &e->tracking.min_frames_in_grid);
  r->Read("velocity_tolerance", &e->tracking.velocity_tolerance);
  r->Read("velocity_tolerance_fraction", &e->tracking.velocity_tolerance_fraction);
  r->Read("focus_object", &e->focus_object);
  r->Read("snapshot_times", &e->snapshot_times);
  r->Finish();
  std::string error;
  if (!e->IsValid(&error)) Invalid(root.file(), "evaluation", error);
}

// The user's SUMO route and additional files, indexed once (std::nullopt when there are none):
// ids the scenario names must be vehicles SUMO will simulate and types it gives an RCS must exist
// (a typo would otherwise fail at run time, or silently pick another vehicle or none).
std::optional<sim::RouteFileIndex> IndexUserFiles(MapReader& root, const std::string& name,
                                                  sim::ScenarioSpec& s) {
  const bool cfg = root.Has("sumo_config");
  if (s.route_files.empty() && s.additional_files.empty()) {
    if (!s.type_rcs.empty())
      throw ConfigError(name +
                        ": key 'traffic.rcs_dbsm' gives vType RCS values, but there are no "
                        "SUMO route or additional files whose vTypes they could be");
    return std::nullopt;
  }
  sim::RouteFileIndex index;
  const auto add = [&](const std::vector<std::string>& files, const char* what, const char* key) {
    try {
      sim::IndexSumoFiles(files, what, &index);
    } catch (const std::invalid_argument& e) {
      throw ConfigError(name + ": key '" + (cfg ? "sumo_config" : key) + "': " + e.what());
    }
  };
  add(s.additional_files, "SUMO additional file", "traffic.additional_files");
  add(s.route_files, "SUMO route file", "traffic.route_files");
  for (const std::string& w : index.warnings) s.warnings.push_back(w);
  for (const auto& [type, rcs] : s.type_rcs) {
    // SUMO's built-in types (DEFAULT_VEHTYPE, DEFAULT_BIKETYPE, ...) need no definition.
    if (index.types.count(type) || type.rfind("DEFAULT_", 0) == 0) continue;
    std::string known;
    for (const std::string& t : index.types) known += (known.empty() ? "'" : ", '") + t + "'";
    throw ConfigError(name + ": key 'traffic.rcs_dbsm." + type +
                      "': no route or additional file "
                      "defines a vType '" +
                      type + "' (expected one of: " + (known.empty() ? "none defined" : known) +
                      ", or DEFAULT_VEHTYPE)");
  }
  const std::string& ego = s.ego.id;
  if (s.ego_from_routes && ego == sim::kAutoEgo) {
    if (index.vehicles.empty() && index.flows.empty())
      throw ConfigError(name +
                        ": key 'ego.from_routes' is 'auto', but the route and additional "
                        "files define no vehicle, trip or flow to choose from");
  } else if (s.ego_from_routes) {
    if (const auto problem = sim::VehicleIdProblem(index, ego))
      throw ConfigError(name + ": key 'ego.from_routes': '" + ego + "' " + *problem +
                        " (expected a vehicle, a trip, FLOW.k for a flow's k-th vehicle, or "
                        "auto; e.g. " +
                        sim::ExampleVehicleIds(index) + ")");
  }
  return index;
}

}  // namespace

void ReadAll(const YAML::Node& doc, const std::string& name, ScenarioConfig* out);

bool EvaluationConfig::IsValid(std::string* error) const {
  FieldCheck c;
  c.InRange("dynamic_threshold", dynamic_threshold, 0.0, 1.0, Interval::kOpen);
  c.Expect(min_cluster_mass >= 0.0, "min_cluster_mass", min_cluster_mass, ">= 0");
  c.Member("dbscan_", dbscan);
  c.Member("", tracking);
  return c.Done(error);
}

Vector2 GridPlacement::CentreOffset(double length_x, double width_y) const {
  const double a = std::isnan(ahead) ? 0.5 * length_x : ahead;
  const double l = std::isnan(left) ? 0.5 * width_y : left;
  // Centre = ego + (ahead - L/2, left - W/2); exactly zero for a centred ego.
  return {a - 0.5 * length_x, l - 0.5 * width_y};
}

std::string_view ToString(GridPlacement::Frame f) {
  switch (f) {
    case GridPlacement::Frame::kWorld:
      return "world";
    case GridPlacement::Frame::kHeading:
      return "heading";
    case GridPlacement::Frame::kFollow:
      break;
  }
  return "follow";
}

filter::FilterParams ScenarioConfig::FilterFor(filter::WeightMode mode) const {
  filter::FilterParams p = filter;
  p.mode = mode;
  // The co-simulation's cycle is its step: the per-cycle factors are per step, as given.
  p.cycle = sim.step_length;
  if (const auto it = birth_velocity_by_mode.find(mode); it != birth_velocity_by_mode.end())
    p.birth_velocity = it->second;
  return p;
}

namespace {

ScenarioConfig LoadDocument(const std::function<YAML::Node()>& parse,
                            const std::filesystem::path& file) {
  const std::string name = file.string();
  YAML::Node doc;
  try {
    doc = parse();
  } catch (const YAML::Exception& e) {
    throw ConfigError(name + ":" + std::to_string(e.mark.line + 1) + ":" +
                      std::to_string(e.mark.column + 1) + ": not valid YAML: " + e.msg);
  }
  ScenarioConfig config;
  config.file = file;
  try {
    ReadAll(doc, name, &config);
  } catch (const YAML::Exception& e) {
    // Conversions inside yaml-cpp (e.g. a non-text map key) still get the file and the place.
    throw ConfigError(name + ":" + std::to_string(e.mark.line + 1) + ":" +
                      std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
  return config;
}

}  // namespace

Override ParseOverride(const std::string& text) {
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw ConfigError("--set '" + text + "': expected KEY=VALUE, e.g. filter.preset=paper");
  return {text.substr(0, eq), text.substr(eq + 1)};
}

namespace {

// Sets `o.key` in `doc` to the YAML value `o.value`, creating maps on the way.
void ApplyOverride(YAML::Node doc, const Override& o) {
  const std::string where = "--set " + o.key + "=" + o.value;
  YAML::Node value;
  try {
    value = YAML::Load(o.value);
  } catch (const YAML::Exception& e) {
    throw ConfigError(where + ": the value is not valid YAML: " + e.msg);
  }
  std::vector<std::string> parts;
  for (std::size_t a = 0;;) {
    const std::size_t b = o.key.find('.', a);
    parts.push_back(o.key.substr(a, b == std::string::npos ? std::string::npos : b - a));
    if (b == std::string::npos) break;
    a = b + 1;
  }
  // yaml-cpp nodes are handles: assigning to `node` would rebind it, so walk with reset().
  YAML::Node node;
  node.reset(doc);
  std::string path;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const std::string& part = parts[i];
    if (part.empty()) throw ConfigError(where + ": empty component in the key");
    path += (path.empty() ? "" : ".") + part;
    const bool last = i + 1 == parts.size();
    if (node.IsSequence()) {
      if (part.find_first_not_of("0123456789") != std::string::npos || part.size() > 6 ||
          std::stoul(part) >= node.size())
        throw ConfigError(where + ": '" + path + "' indexes a list of " +
                          std::to_string(node.size()) + " entries; expected an index 0.." +
                          std::to_string(node.size() == 0 ? 0 : node.size() - 1));
      if (last) {
        node[std::stoul(part)] = value;
        return;
      }
      YAML::Node next = node[std::stoul(part)];
      node.reset(next);
      continue;
    }
    if (!node.IsMap() && !node.IsNull())
      throw ConfigError(where + ": '" + path.substr(0, path.size() - part.size() - 1) +
                        "' is not a map in the scenario file");
    if (last) {
      node[part] = value;
      return;
    }
    YAML::Node next = node[part];
    if (!next.IsDefined() || next.IsNull()) {  // a section the file does not have yet
      node[part] = YAML::Node(YAML::NodeType::Map);
      next.reset(node[part]);
    }
    node.reset(next);
  }
}

}  // namespace

ScenarioConfig LoadScenario(const std::filesystem::path& file,
                            const std::vector<Override>& overrides) {
  // Bounded, and a FIFO or device is refused before it could block (core/input_file.hpp).
  std::string text;
  try {
    text = ReadInputText(file, "scenario file");
  } catch (const std::invalid_argument& e) {
    throw ConfigError(e.what());
  }
  return LoadDocument(
      [&] {
        YAML::Node doc = YAML::Load(text);
        for (const Override& o : overrides) ApplyOverride(doc, o);
        return doc;
      },
      file);
}

ScenarioConfig LoadScenarioText(const std::string& text, const std::filesystem::path& file) {
  return LoadDocument([&] { return YAML::Load(text); }, file);
}

nlohmann::json ConfigToJson(const ScenarioConfig& c) {
  nlohmann::json j;
  j["scenario_file"] = c.file.string();
  j["scenario"] = c.sim.name;
  j["overrides"] = c.overrides;
  j["seed"] = c.sim.seed;
  j["duration_s"] = c.sim.duration;
  j["step_length_s"] = c.sim.step_length;
  j["sensors"]["accuracy"] = c.radar.accuracy;
  j["sensors"]["noise"] = c.radar.options.noise;
  j["sensors"]["false_alarms"] = c.radar.options.false_alarms;
  j["sensors"]["occlusion"] = c.radar.options.occlusion;
  // Only when on: a run with multipath off writes the same config.json as before it existed.
  if (const radar::MultipathParams& mp = c.radar.options.multipath; mp.enabled)
    j["sensors"]["multipath"] = {{"enabled", mp.enabled},
                                 {"rails", mp.rails},
                                 {"vehicles", mp.vehicles},
                                 {"rail_loss_db", mp.rail_loss_db},
                                 {"vehicle_loss_db", mp.vehicle_loss_db},
                                 {"vehicle_min_length", mp.vehicle_min_length},
                                 {"max_bounces", mp.max_bounces},
                                 {"min_pd", mp.min_pd}};
  for (const auto& s : c.radar.sensors) {
    nlohmann::json sj = {{"name", s.name},
                         {"mount",
                          {{"x", s.mount.position.x()},
                           {"y", s.mount.position.y()},
                           {"yaw_deg", RadToDeg(s.mount.yaw)}}}};
    WriteFields(kSensorDoubles, s, &sj);
    WriteSensorProfile(s, &sj);
    j["sensors"]["rig"].push_back(sj);
  }
  WriteFields(kFilterDoubles, c.filter, &j["filter"]);
  WriteFields(kFilterInts, c.filter, &j["filter"]);
  j["filter"]["mode"] = filter::ToString(c.filter.mode);
  j["filter"]["preset"] = c.filter_preset.empty() ? "default" : c.filter_preset;
  j["filter"]["zero_likelihood"] = filter::ToString(c.filter.zero_likelihood);
  j["filter"]["velocity_likelihood"] = filter::ToString(c.filter.velocity_likelihood);
  j["filter"]["normalisation"] = filter::ToString(c.filter.normalisation);
  j["filter"]["frame"] = ToString(c.grid.frame);
  if (c.grid.frame == GridPlacement::Frame::kFollow)
    j["filter"]["realign_deg"] = c.grid.realign_deg;
  const Vector2 off = c.grid.CentreOffset(c.filter.length_x, c.filter.width_y);
  j["filter"]["ahead"] = 0.5 * c.filter.length_x + off.x();
  j["filter"]["left"] = 0.5 * c.filter.width_y + off.y();
  // Per mode always (the resolved value each filter runs with), so runs compare key by key.
  for (filter::WeightMode m :
       {filter::WeightMode::kPosition, filter::WeightMode::kVelocity, filter::WeightMode::kDual})
    j["filter"]["birth_velocity"][std::string(filter::ToString(m))] =
        filter::ToString(c.FilterFor(m).birth_velocity);
  auto& e = j["evaluation"];
  e["dynamic_threshold"] = c.evaluation.dynamic_threshold;
  e["min_cluster_mass"] = c.evaluation.min_cluster_mass;
  e["dbscan"] = c.evaluation.dbscan;
  e["tracking"] = c.evaluation.tracking;
  e["focus_object"] = c.evaluation.focus_object;
  e["snapshot_times"] = c.evaluation.snapshot_times;
  return j;
}

void ReadAll(const YAML::Node& doc, const std::string& name, ScenarioConfig* out) {
  ScenarioConfig& config = *out;
  MapReader root(doc, name, "");
  config.sim.file = name;
  ReadSim(root, &config.sim);
  if (config.sim.name.empty()) config.sim.name = std::filesystem::path(name).stem().string();
  std::string error;
  if (!config.sim.IsValid(&error)) Invalid(name, "", error);
  const std::optional<sim::RouteFileIndex> routes = IndexUserFiles(root, name, config.sim);
  ReadRadar(root, config.sim, &config.radar);
  ReadFilter(root, &config);
  ReadEvaluation(root, &config.evaluation);
  root.Finish();
  // Names the evaluation uses must exist: a typo would silently pick another vehicle.
  const auto& focus = config.evaluation.focus_object;
  if (!focus.empty()) {
    bool found = focus == config.sim.ego.id;
    for (const auto& v : config.sim.vehicles) found = found || v.id == focus;
    // A flow's vehicles are named by SUMO "<flow id>.<k>".
    for (const auto& f : config.sim.flows)
      found =
          found || (focus.rfind(f.id + ".", 0) == 0 && focus.size() > f.id.size() + 1 &&
                    focus.find_first_not_of("0123456789", f.id.size() + 1) == std::string::npos);
    // A vehicle of the user's route files (or of one of their flows).
    if (!found && routes) found = !sim::VehicleIdProblem(*routes, focus);
    if (!found || focus == config.sim.ego.id)
      throw ConfigError(name + ": key 'evaluation.focus_object' names '" + focus +
                        "', which is no vehicle of the scenario (expected an id of "
                        "traffic.vehicles, or <flow id>.<k> for the k-th vehicle of a flow)");
  }
  for (double t : config.evaluation.snapshot_times)
    if (!(t > 0.0 && t <= config.sim.duration))
      throw ConfigError(
          name + ": key 'evaluation.snapshot_times' holds " + std::to_string(t) +
          " s, outside the run (0, duration = " + std::to_string(config.sim.duration) + "] s");
}

}  // namespace dualgrid::scenario
