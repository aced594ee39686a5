#include <filesystem>
#include <functional>

#include "dualgrid/sim/opendrive.hpp"
#include "dualgrid/sim/sumo_simulation.hpp"
#include "sections.hpp"

namespace dualgrid::scenario::detail {

namespace {

using PathFn = std::function<std::string(const std::string&)>;

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

// `begin`: the scenario's key wins over the configuration's <begin> (as SUMO read it).
void ReadBegin(MapReader& root, const sim::SumoConfigInputs* cfg, sim::ScenarioSpec* s) {
  if (cfg) {
    s->begin = cfg->begin;
    s->begin_source = "sumo_config";
    s->config_end = cfg->end;
  }
  std::optional<double> begin;
  root.Read("begin", &begin);
  if (begin) {
    s->begin = *begin;
    s->begin_source = "scenario";
  }
}

// `sumo_config` (its network, files, begin and end, as SUMO reads them) or `network`; an
// OpenDRIVE map is converted into the cache (sim/opendrive.hpp).
void ReadSources(MapReader& root, const PathFn& relative_to_file, sim::ScenarioSpec* s) {
  std::optional<sim::SumoConfigInputs> in;
  if (root.Has("sumo_config")) {
    if (root.Has("network"))
      root.Fail("network", "must not be given with sumo_config (whose net-file is the network)");
    std::string cfg;
    root.Read("sumo_config", &cfg);
    try {
      in = sim::ReadSumoConfig(relative_to_file(cfg));
    } catch (const std::exception& e) {
      root.Fail("sumo_config", e.what());
    }
    s->network = in->net_file.string();
    for (const auto& f : in->route_files) s->route_files.push_back(f.string());
    for (const auto& f : in->additional_files) s->additional_files.push_back(f.string());
    if (in->remote_port)
      s->warnings.push_back(root.file() + ": key 'sumo_config': its <remote-port value=\"" +
                            *in->remote_port +
                            "\"/> (TraCI) is not opened: dualgrid runs SUMO in process "
                            "(libsumo) and waits for no client");
  } else {
    root.Require("network", &s->network);
  }
  // A network given as a file (ending in .xml or .xodr) is read relative to the scenario file, so
  // a scenario and its network can move together; a bare name is one of the built networks.
  if (const std::filesystem::path net(s->network);
      (sim::IsNetworkPath(s->network) || sim::IsOpenDrive(s->network)) && net.is_relative())
    s->network = relative_to_file(s->network);
  if (sim::IsOpenDrive(s->network)) {
    s->network_source = s->network;
    try {
      s->network = sim::ConvertOpenDrive(s->network).string();
    } catch (const std::exception& e) {
      root.Fail("network", e.what());
    }
  }
  ReadBegin(root, in ? &*in : nullptr, s);
  root.Read("duration", &s->duration);
  root.Read("step_length", &s->step_length);
  if (in && in->step_length && *in->step_length != s->step_length)
    s->warnings.push_back(root.file() + ": key 'sumo_config': its step-length " +
                          Shown(*in->step_length) + " s is replaced by step_length " +
                          Shown(s->step_length) + " s (the radar cycle)");
}

// `ego`: a vehicle the scenario places, or `from_routes` (a vehicle of the user's files, or auto).
void ReadEgo(MapReader& root, sim::ScenarioSpec* s) {
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
}

// `traffic`: the user's SUMO files, RCS per vType, the scenario's vehicles and flows, random trips.
void ReadTraffic(MapReader& root, const PathFn& relative_to_file, sim::ScenarioSpec* s) {
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
    if (traffic->Has("random_trips")) {
      sim::RandomTripsSpec trips;
      if (auto r = traffic->Map("random_trips")) {
        r->Read("period", &trips.period);
        r->Finish();
      }
      if (!(trips.period > 0.0 && trips.period <= 3600.0))
        traffic->Fail("random_trips",
                      "expected a period in (0, 3600] s, got " + Shown(trips.period));
      s->random_trips = trips;
    }
    traffic->Finish();
  }
  // A scenario that gives no traffic at all and lets `auto` choose the ego gets random traffic.
  if (s->ego_from_routes && s->ego.id == sim::kAutoEgo && s->route_files.empty() &&
      s->additional_files.empty() && s->vehicles.empty() && s->flows.empty())
    if (!s->random_trips) s->random_trips = sim::RandomTripsSpec{};
}

// `actions` and `obstacles`.
void ReadActionsAndObstacles(MapReader& root, sim::ScenarioSpec* s) {
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

void ReadSim(MapReader& root, sim::ScenarioSpec* s) {
  root.Read("name", &s->name);
  root.Read("description", &s->description);
  const std::filesystem::path here = std::filesystem::path(root.file()).parent_path();
  const PathFn relative_to_file = [&](const std::string& p) {
    return std::filesystem::absolute(here / p).lexically_normal().string();
  };
  ReadSources(root, relative_to_file, s);
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
  ReadEgo(root, s);
  ReadTraffic(root, relative_to_file, s);
  ReadActionsAndObstacles(root, s);
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
    s.ego_departure = sim::DepartureOf(index, ego);  // checked against the run's window
  }
  return index;
}

}  // namespace dualgrid::scenario::detail
