#include "dualgrid/scenario/loader.hpp"

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
    r.Read("speed_factor_dev", &t.speed_factor_dev);
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

}  // namespace

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
  MapReader root(doc, name, "");
  ReadSim(root, &config.sim);
  if (config.sim.name.empty()) config.sim.name = file.stem().string();
  root.Finish();
  std::string error;
  if (!config.sim.IsValid(&error)) {
    const auto colon = error.find(": ");
    throw ConfigError(name + ": key '" + error.substr(0, colon) + "' " + error.substr(colon + 2));
  }
  return config;
}

}  // namespace dualgrid::scenario
