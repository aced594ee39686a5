#include "dualgrid/scenario/loader.hpp"

#include <algorithm>

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

void ReadSim(MapReader& root, sim::ScenarioSpec* s) {
  root.Read("name", &s->name);
  root.Read("description", &s->description);
  root.Require("network", &s->network);
  root.Read("duration", &s->duration);
  root.Read("step_length", &s->step_length);
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
  ReadVehicle(*ego, &s->ego);
  if (s->ego.desired_speed)
    ego->Fail("desired_speed", "is not used for the ego: set ego.speed_policy.speed");
  if (auto sp = ego->Map("speed_policy")) {
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

void ReadSensorFields(MapReader& r, radar::SensorParams* p) {
  if (auto m = r.Map("mount")) {
    m->Read("x", &p->mount.position.x());
    m->Read("y", &p->mount.position.y());
    m->ReadDegrees("yaw_deg", &p->mount.yaw);
    m->Finish();
  }
  r.ReadDegrees("fov_deg", &p->fov);
  r.Read("min_range", &p->min_range);
  r.Read("max_range", &p->max_range);
  r.Read("min_range_rate", &p->min_range_rate);
  r.Read("max_range_rate", &p->max_range_rate);
  r.Read("range_resolution", &p->range_resolution);
  r.ReadDegrees("azimuth_resolution_deg", &p->azimuth_resolution);
  r.Read("range_rate_resolution", &p->range_rate_resolution);
  r.Read("range_bias_fraction", &p->range_bias_fraction);
  r.Read("azimuth_bias_fraction", &p->azimuth_bias_fraction);
  r.Read("range_rate_bias_fraction", &p->range_rate_bias_fraction);
  r.Read("reference_range", &p->reference_range);
  r.Read("reference_rcs_dbsm", &p->reference_rcs_dbsm);
  r.Read("reference_pd", &p->reference_pd);
  r.Read("false_alarm_rate", &p->false_alarm_rate);
  r.Read("update_period", &p->update_period);
}

// Turns "field: message" from an IsValid into a ConfigError under `section`.
[[noreturn]] void Invalid(const std::string& file, const std::string& section,
                          const std::string& error) {
  // Validators write "field: message" or "field message".
  auto colon = error.find(": ");
  std::size_t skip = 2;
  if (colon == std::string::npos) colon = error.find(' '), skip = 1;
  const std::string field = colon == std::string::npos ? error : error.substr(0, colon);
  const std::string message =
      colon == std::string::npos ? "is invalid" : error.substr(colon + skip);
  throw ConfigError(file + ": key '" + (section.empty() ? field : section + "." + field) + "' " +
                    message);
}

void ReadRadar(MapReader& root, const sim::ScenarioSpec& spec, RadarConfig* radar) {
  const auto& ego_type = spec.vehicle_types.at(spec.ego.type);
  radar->sensors = radar::DefaultRig(ego_type.length, ego_type.width);
  auto section = root.Map("sensors");
  if (!section) return;
  std::string rig = "default";
  section->Read("rig", &rig);
  if (rig != "default") section->Fail("rig", "expected 'default', got '" + rig + "'");
  section->Read("noise", &radar->options.noise);
  section->Read("false_alarms", &radar->options.false_alarms);
  section->Read("occlusion", &radar->options.occlusion);
  auto names = [&] {
    std::string all;
    for (const auto& s : radar->sensors) all += (all.empty() ? "" : ", ") + s.name;
    return all;
  };
  for (auto& [name, r] : section->NamedMaps("overrides")) {
    auto it = std::find_if(radar->sensors.begin(), radar->sensors.end(),
                           [&](const radar::SensorParams& s) { return s.name == name; });
    if (it == radar->sensors.end())
      throw ConfigError(r.file() + ": key '" + r.path() + "' names unknown sensor '" + name +
                        "' (expected one of: " + names() + ")");
    ReadSensorFields(r, &*it);
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

void ReadFilter(MapReader& root, filter::FilterParams* f) {
  auto r = root.Map("filter");
  if (!r) return;
  r->Read("length_x", &f->length_x);
  r->Read("width_y", &f->width_y);
  r->Read("resolution", &f->resolution);
  r->Read("num_particles", &f->num_particles);
  r->Read("num_birth", &f->num_birth);
  r->Read("process_noise_position", &f->process_noise_position);
  r->Read("process_noise_velocity", &f->process_noise_velocity);
  r->Read("persistence", &f->persistence);
  r->Read("birth_probability", &f->birth_probability);
  r->Read("birth_max_tangential_speed", &f->birth_max_tangential_speed);
  r->Read("birth_sigma_radial", &f->birth_sigma_radial);
  r->Read("max_speed", &f->max_speed);
  r->Read("sigma_f", &f->sigma_f);
  r->Read("sigma_static_distance", &f->sigma_static_distance);
  r->Read("sigma_static_velocity", &f->sigma_static_velocity);
  r->Read("sigma_v", &f->sigma_v);
  r->Read("cutoff_sigmas", &f->cutoff_sigmas);
  r->Read("occupied_mass", &f->occupied_mass);
  r->Read("free_mass", &f->free_mass);
  r->Read("free_mass_no_return", &f->free_mass_no_return);
  r->ReadDegrees("free_angle_bin_deg", &f->free_angle_bin);
  r->Read("free_bin_dilation", &f->free_bin_dilation);
  r->Read("free_decay", &f->free_decay);
  r->Read("static_persistence", &f->static_persistence);
  r->Read("static_gain", &f->static_gain);
  r->Read("static_speed", &f->static_speed);
  r->Read("decay_eps", &f->decay_eps);
  std::string mode(filter::ToString(f->mode));
  r->Read("mode", &mode);
  const auto parsed = filter::ParseWeightMode(mode);
  if (!parsed) r->Fail("mode", "expected 'position', 'velocity' or 'dual', got '" + mode + "'");
  f->mode = *parsed;
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
  r->Read("focus_object", &e->focus_object);
  r->Read("snapshot_times", &e->snapshot_times);
  r->Finish();
  std::string error;
  if (!e->IsValid(&error)) Invalid(root.file(), "evaluation", error);
}

}  // namespace

void ReadAll(const YAML::Node& doc, const std::string& name, ScenarioConfig* out);

bool EvaluationConfig::IsValid(std::string* error) const {
  if (!(dynamic_threshold > 0.0 && dynamic_threshold < 1.0)) {
    if (error) *error = "dynamic_threshold: must be in (0, 1)";
    return false;
  }
  if (!(min_cluster_mass >= 0.0)) {
    if (error) *error = "min_cluster_mass: must be >= 0";
    return false;
  }
  std::string e;
  if (!dbscan.IsValid(&e)) {
    if (error) *error = "dbscan_" + e;
    return false;
  }
  if (!tracking.IsValid(&e)) {
    if (error) *error = e;
    return false;
  }
  return true;
}

ScenarioConfig LoadScenario(const std::filesystem::path& file) {
  const std::string name = file.string();
  if (!std::filesystem::is_regular_file(file))
    throw ConfigError(name + ": scenario file not found");
  YAML::Node doc;
  try {
    doc = YAML::LoadFile(name);
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

void ReadAll(const YAML::Node& doc, const std::string& name, ScenarioConfig* out) {
  ScenarioConfig& config = *out;
  MapReader root(doc, name, "");
  ReadSim(root, &config.sim);
  if (config.sim.name.empty()) config.sim.name = std::filesystem::path(name).stem().string();
  std::string error;
  if (!config.sim.IsValid(&error)) Invalid(name, "", error);
  ReadRadar(root, config.sim, &config.radar);
  ReadFilter(root, &config.filter);
  ReadEvaluation(root, &config.evaluation);
  root.Finish();
}

}  // namespace dualgrid::scenario
