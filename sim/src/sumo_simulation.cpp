#include "dualgrid/sim/sumo_simulation.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <optional>
#include <set>
#include <stdexcept>

#include <libsumo/libsumo.h>

#include "auto_ego_run.hpp"
#include "dualgrid/core/input_file.hpp"
#include "dualgrid/core/random.hpp"
#include "dualgrid/core/text.hpp"
#include "dualgrid/core/write_file.hpp"
#include "dualgrid/sim/conversions.hpp"
#include "dualgrid/sim/random_trips.hpp"
#include "dualgrid/sim/sumo_additional.hpp"
#include "dualgrid/sim/xml_scan.hpp"

namespace dualgrid::sim {
namespace {

// libsumo keeps its simulation in process-global state.
std::atomic<bool> g_simulation_alive{false};

// libsumo messages may span lines; the CLI reports errors in one line.
std::string OneLine(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

// Numbers in the route file, SUMO's options and messages: 10 significant digits.
std::string Num(double v) { return FormatSignificant(v, 10); }

// Lane change mode 256: no autonomous lane changes; scripted changeLane requests still avoid
// immediate collisions (SUMO docs, "lane change mode" bits 8-9).
constexpr int kLaneChangeModeScriptedOnly = 256;

// A look at a network file before SUMO parses it: SUMO's own messages for a file that is not
// XML or is cut short ("invalid document structure", "unexpected end of input") name no file.
// A SUMO network is one <net> element; the whole document is parsed once (expat, linear), so a
// truncated file is caught with its line.
void CheckNetworkFile(const std::filesystem::path& path) {
  const std::string hint = " (build it with netconvert; see docs/scenarios.md)";
  try {
    std::string root;
    ScanXml(path, "network file", [&](const XmlElement& e) {
      if (e.depth() == 0) root = e.tag();
      return e.depth() == 0 ? root == "net" : true;
    });
    if (root != "net")
      throw std::invalid_argument(path.string() + ": network file is not a SUMO network (root <" +
                                  root + ">, expected <net>)");
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(e.what() + hint);
  }
}

}  // namespace

NetworkDirLocation FindNetworkDir(const std::filesystem::path& anchor,
                                  const std::filesystem::path& package_dir) {
  namespace fs = std::filesystem;
  if (const char* env = std::getenv("DUALGRID_NETWORK_DIR"); env && *env)
    return {env, "DUALGRID_NETWORK_DIR"};
  std::error_code ec;
  const fs::path self = anchor.empty() ? fs::read_symlink("/proc/self/exe", ec) : anchor;
  if (!ec && !self.empty()) {
    // PREFIX/bin/dualgrid -> PREFIX/share/dualgrid/networks (also PREFIX/lib/... for a library).
    const fs::path installed = self.parent_path().parent_path() / "share" / "dualgrid" / "networks";
    if (fs::is_directory(installed, ec)) return {installed, "installed"};
  }
  if (!package_dir.empty()) return {package_dir, "package"};
#ifdef DUALGRID_NETWORK_DIR
  if (fs::is_directory(DUALGRID_NETWORK_DIR, ec)) return {DUALGRID_NETWORK_DIR, "build tree"};
#endif
  return {"networks", "none"};
}

bool IsNetworkPath(const std::string& network) {
  return network.ends_with(".xml") || network.ends_with(".xml.gz") ||
         network.find('/') != std::string::npos;
}

std::filesystem::path ResolveNetwork(const std::string& network,
                                     const std::filesystem::path& network_dir) {
  std::filesystem::path p = network;
  if (!IsNetworkPath(network)) p = network_dir / (network + ".net.xml");
  // Present but unusable (a folder, a FIFO, a link loop): refused naming why, not "not found".
  if (InputExists(p)) return CheckInputFile(p, "network file"), p;
  if (IsNetworkPath(network))
    throw std::invalid_argument("network '" + network + "' not found: no file " + p.string() +
                                " (a path in a scenario is read relative to the scenario file)");
  std::string built;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(network_dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.size() > 8 && name.ends_with(".net.xml"))
      built += (built.empty() ? "" : ", ") + name.substr(0, name.size() - 8);
  }
  throw std::invalid_argument(
      "network '" + network + "' not found: no file " + p.string() + " (" +
      (built.empty() ? "no networks built there: build the project, or set DUALGRID_NETWORK_DIR"
                     : "built networks: " + built) +
      "; or give a path to a .net.xml file, relative to the scenario file)");
}

namespace {

// The types the scenario's own vehicles use, the only ones written to its route file: a route
// file of the user may define a type of the same name (SUMO refuses a second definition, and
// that name then means the user's type).
std::set<std::string> OwnTypes(const ScenarioSpec& spec) {
  std::set<std::string> used;
  if (!spec.ego_from_routes) used.insert(spec.ego.type);
  for (const VehicleSpec& v : spec.vehicles) used.insert(v.type);
  for (const FlowSpec& f : spec.flows) used.insert(f.type);
  return used;
}

}  // namespace

void WriteRouteFile(const ScenarioSpec& spec, const std::filesystem::path& path) {
  std::ofstream out(path);
  if (!out)
    throw std::runtime_error("cannot write route file " + path.string() + ": " + SystemReason());
  // The name goes into an XML comment, where "--" is not allowed: escaped like an attribute, with
  // dashes spelled out.
  std::string name = XmlEscape(spec.name);
  for (std::size_t i = name.find('-'); i != std::string::npos; i = name.find('-', i + 5))
    name.replace(i, 1, "&#45;");
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<!-- generated by dualgrid from scenario '"
      << name << "' -->\n<routes>\n";
  // Desired speeds are set per vehicle through maxSpeed (see ApplyDepartures); a speed factor of
  // 1.5 keeps the lane limits from capping them below 130 km/h.
  const std::set<std::string> used = OwnTypes(spec);
  for (const auto& [name, t] : spec.vehicle_types) {
    if (!used.count(name)) continue;
    out << "  <vType id=\"" << XmlEscape(name) << "\" length=\"" << Num(t.length) << "\" width=\""
        << Num(t.width) << "\" maxSpeed=\"" << Num(t.max_speed) << "\" accel=\"" << Num(t.accel)
        << "\" decel=\"" << Num(t.decel) << "\" speedFactor=\"1.5\" speedDev=\"0\" sigma=\"0\""
        << " vClass=\"" << XmlEscape(t.vclass) << "\" minGap=\"2.5\" lcOvertakeRight=\""
        << (t.overtake_right ? 1 : 0) << "\"/>\n";
  }
  for (const auto& [name, edges] : spec.routes) {
    out << "  <route id=\"" << XmlEscape(name) << "\" edges=\"";
    for (std::size_t i = 0; i < edges.size(); ++i) out << (i ? " " : "") << XmlEscape(edges[i]);
    out << "\"/>\n";
  }
  // SUMO requires vehicles and flows sorted by departure time.
  struct Entry {
    double depart;
    std::string xml;
  };
  std::vector<Entry> entries;
  // The scenario's times count from its begin (run time); SUMO's route file is on SUMO's clock.
  const double t0 = spec.begin;
  auto vehicle_xml = [t0](const VehicleSpec& v) {
    return "  <vehicle id=\"" + XmlEscape(v.id) + "\" type=\"" + XmlEscape(v.type) + "\" route=\"" +
           XmlEscape(v.route) + "\" depart=\"" + Num(t0 + v.depart) + "\" departLane=\"" +
           std::to_string(v.lane) + "\" departPos=\"" + Num(v.position) + "\" departSpeed=\"" +
           Num(v.speed) + "\"/>\n";
  };
  if (!spec.ego_from_routes) entries.push_back({spec.ego.depart, vehicle_xml(spec.ego)});
  for (const VehicleSpec& v : spec.vehicles) entries.push_back({v.depart, vehicle_xml(v)});
  for (const FlowSpec& f : spec.flows) {
    entries.push_back(
        {f.begin, "  <flow id=\"" + XmlEscape(f.id) + "\" type=\"" + XmlEscape(f.type) +
                      "\" route=\"" + XmlEscape(f.route) + "\" begin=\"" + Num(t0 + f.begin) +
                      "\" end=\"" + Num(t0 + f.end) + "\" period=\"" + Num(f.period) +
                      "\" departLane=\"" + XmlEscape(f.lane) + "\" departPos=\"" + Num(f.position) +
                      "\" departSpeed=\"" + Num(0.5 * (f.speed_min + f.speed_max)) + "\"/>\n"});
  }
  std::stable_sort(entries.begin(), entries.end(),
                   [](const Entry& a, const Entry& b) { return a.depart < b.depart; });
  for (const Entry& e : entries) out << e.xml;
  out << "</routes>\n";
  if (!out)
    throw std::runtime_error("cannot write route file " + path.string() + ": " + SystemReason());
}

namespace {

// SUMO's command line for `spec` (the scenario's route file first, then the user's files;
// `additional` as prepared, comma-separated, or empty).
std::vector<std::string> SumoArgs(const ScenarioSpec& spec,
                                  const std::filesystem::path& network_file,
                                  const std::string& route_files, const std::string& additional,
                                  const std::filesystem::path& log) {
  std::vector<std::string> args = {"sumo",
                                   "--net-file",
                                   network_file.string(),
                                   "--route-files",
                                   route_files,
                                   "--step-length",
                                   Num(spec.step_length),
                                   "--seed",
                                   std::to_string(spec.seed % 2147483647),
                                   "--lanechange.duration",
                                   Num(spec.lane_change_duration),
                                   "--begin",
                                   Num(spec.begin),
                                   "--end",
                                   Num(spec.begin + spec.duration + 1.0),
                                   "--xml-validation",
                                   "never",
                                   "--no-step-log",
                                   "true",
                                   "--duration-log.disable",
                                   "true",
                                   "--message-log",
                                   log.string(),
                                   "--no-warnings",
                                   "true",
                                   "--time-to-teleport",
                                   "-1",
                                   "--collision.action",
                                   "warn",
                                   "--threads",
                                   "1"};
  if (!additional.empty()) {
    args.push_back("--additional-files");
    args.push_back(additional);
  }
  return args;
}

}  // namespace

std::string RunWindow(const ScenarioSpec& spec) {
  return "SUMO time [" + Num(spec.begin) + ", " + Num(spec.begin + spec.duration) +
         "] s (run time [0, " + Num(spec.duration) + "] s)";
}

namespace {

// Why `auto` found no ego: no road vehicle departed in the run.
std::string NoAutoEgo(const ScenarioSpec& spec) {
  return "scenario '" + spec.name +
         "': ego.from_routes is auto, but no road vehicle of the route files departed within " +
         RunWindow(spec) +
         (spec.begin > 0.0 ? "" : "; a scenario that starts later needs `begin` or --begin") +
         " (vehicles that depart before the begin are skipped, as SUMO skips them)";
}

}  // namespace

SumoSimulation::SumoSimulation(const ScenarioSpec& spec, const std::filesystem::path& network_file,
                               const std::filesystem::path& work_dir)
    : spec_(spec), log_path_(work_dir / "sumo.log"), own_types_(OwnTypes(spec)) {
  std::string error;
  if (!spec_.IsValid(&error))
    throw std::invalid_argument("scenario '" + spec_.name + "': " + error);
  if (g_simulation_alive.exchange(true))
    throw std::logic_error("libsumo runs one simulation per process; one is already running");
  std::string route_files, additional_list;
  try {
    CheckNetworkFile(network_file);
    std::filesystem::create_directories(work_dir);
    const auto routes = work_dir / "routes.rou.xml";
    WriteRouteFile(spec_, routes);
    // Random traffic (randomTrips.py) when the scenario asks for it, as a route file of its own.
    if (spec_.random_trips)
      spec_.route_files.push_back(WriteRandomTrips(network_file, spec_, work_dir).string());
    // The scenario's own vehicles first, then the user's SUMO route files as they are.
    route_files = routes.string();
    for (const std::string& f : spec_.route_files) route_files += "," + f;
    // The user's additional files, their outputs moved into the run folder.
    const PreparedAdditionalFiles additional =
        PrepareAdditionalFiles(spec_.additional_files, work_dir);
    redirected_outputs_ = additional.outputs;
    for (const std::string& f : additional.files)
      additional_list += (additional_list.empty() ? "" : ",") + f;
  } catch (...) {
    g_simulation_alive = false;
    throw;
  }
  std::sort(spec_.actions.begin(), spec_.actions.end(),
            [](const ActionSpec& a, const ActionSpec& b) { return a.time < b.time; });
  try {
    if (spec_.ego_from_routes && spec_.ego.id == kAutoEgo) {
      auto_choice_ =
          ChooseAutoEgo(spec_, SumoArgs(spec_, network_file, route_files, additional_list,
                                        work_dir / "sumo_auto_ego.log"));
      if (auto_choice_) spec_.ego.id = auto_choice_->id;
    }
    if (!spec_.ego_from_routes || spec_.ego.id != kAutoEgo)
      libsumo::Simulation::start(
          SumoArgs(spec_, network_file, route_files, additional_list, log_path_));
  } catch (const std::exception& e) {
    g_simulation_alive = false;
    // SUMO refuses what it is given (the network, a route, a vehicle): bad input.
    throw std::invalid_argument("SUMO refused scenario '" + spec_.name + "' on network " +
                                network_file.string() + ": " + OneLine(e.what()) + " (see " +
                                log_path_.string() + ")");
  }
  if (spec_.ego.id == kAutoEgo && spec_.ego_from_routes) {
    g_simulation_alive = false;
    throw std::invalid_argument(NoAutoEgo(spec_));
  }
  try {
    CheckAgainstNetwork();
  } catch (...) {
    libsumo::Simulation::close();
    g_simulation_alive = false;
    throw;
  }
}

void SumoSimulation::CheckAgainstNetwork() const {
  const auto fail = [&](const std::string& key, const std::string& what) {
    throw std::invalid_argument((spec_.file.empty() ? "" : spec_.file + ": ") + "key '" + key +
                                "' " + what);
  };
  const std::vector<std::string> edges = libsumo::Edge::getIDList();
  const std::set<std::string> known(edges.begin(), edges.end());
  for (const auto& [name, route] : spec_.routes) {
    for (std::size_t i = 0; i < route.size(); ++i) {
      if (!known.count(route[i]))
        fail("routes." + name, "names edge '" + route[i] + "', which is not in the network");
      // Consecutive edges must be connected: SUMO would only say so when a vehicle departs.
      if (i > 0 && libsumo::Simulation::findRoute(route[i - 1], route[i]).edges.size() != 2)
        fail("routes." + name, "has edges '" + route[i - 1] + "' and '" + route[i] +
                                   "' that are not connected (no lane of the first leads into the "
                                   "second)");
    }
  }
  // A departure position past the end of the first edge would be clamped by SUMO to its end.
  const auto check_vehicle = [&](const VehicleSpec& v, const std::string& key) {
    const std::string& edge = spec_.routes.at(v.route).front();
    const int lanes = libsumo::Edge::getLaneNumber(edge);
    if (v.lane >= lanes)
      fail(key + ".lane", "is " + std::to_string(v.lane) + ", but edge '" + edge + "' has " +
                              std::to_string(lanes) + " lane(s) (0 is the rightmost)");
    const double length = libsumo::Lane::getLength(edge + "_" + std::to_string(v.lane));
    if (v.position > length)
      fail(key + ".position", "is " + Num(v.position) + " m, beyond the end of edge '" + edge +
                                  "' (" + Num(length) +
                                  " m long); positions are along the "
                                  "route's first edge");
  };
  if (!spec_.ego_from_routes) check_vehicle(spec_.ego, "ego");
  for (std::size_t i = 0; i < spec_.vehicles.size(); ++i)
    check_vehicle(spec_.vehicles[i], "traffic.vehicles[" + std::to_string(i) + "]");
}

void SumoSimulation::Close() {
  if (closed_) return;
  closed_ = true;
  try {
    libsumo::Simulation::close();
  } catch (...) {
    // Closing after a SUMO error may throw again; the run's own results are complete by now.
  }
  g_simulation_alive = false;
}

SumoSimulation::~SumoSimulation() { Close(); }

const SumoSimulation::LaneGeometry& SumoSimulation::Lane(const std::string& lane_id) {
  auto it = lanes_.find(lane_id);
  if (it != lanes_.end()) return it->second;
  LaneGeometry g;
  for (const auto& p : libsumo::Lane::getShape(lane_id).value) {
    const Position q(p.x, p.y);
    g.s.push_back(g.points.empty() ? 0.0 : g.s.back() + (q - g.points.back()).norm());
    g.points.push_back(q);
  }
  return lanes_.emplace(lane_id, std::move(g)).first->second;
}

VehicleState SumoSimulation::ReadVehicle(const std::string& id) {
  using V = libsumo::Vehicle;
  VehicleState v;
  v.id = id;
  // SUMO names a vehicle's private copy of its type "<type>@<vehicle>" once a vehicle-level
  // parameter (its max speed) is changed.
  v.type = V::getTypeID(id);
  v.type = v.type.substr(0, v.type.find('@'));
  const VehicleTypeSpec& t = TypeOf(id, v.type);
  const auto pos = V::getPosition(id);
  const double yaw = SumoAngleToYaw(V::getAngle(id));
  v.box = {FrontBumperToCenter(Position(pos.x, pos.y), yaw, t.length), yaw, t.length, t.width};
  v.rcs_dbsm = t.rcs_dbsm;
  v.speed = V::getSpeed(id);
  v.lateral_speed = V::getLateralSpeed(id);
  v.lane = V::getLaneID(id);
  // SUMO's speed is along the lane and its lateral speed across it, so the lane direction at the
  // box centre (not the vehicle heading, which tilts during lane changes) turns them into a
  // world velocity.
  const LaneGeometry& lane = Lane(v.lane);
  double lane_yaw = yaw;
  if (lane.points.size() >= 2) {
    const double s = std::max(0.0, V::getLanePosition(id) - 0.5 * t.length);
    std::size_t k = std::upper_bound(lane.s.begin(), lane.s.end(), s) - lane.s.begin();
    k = std::clamp<std::size_t>(k, 1, lane.points.size() - 1);
    const Vector2 d = lane.points[k] - lane.points[k - 1];
    lane_yaw = std::atan2(d.y(), d.x());
  }
  v.velocity = LaneSpeedsToVelocity(v.speed, v.lateral_speed, lane_yaw);
  v.lane_yaw = lane_yaw;
  if (auto it = previous_yaw_.find(id); it != previous_yaw_.end())
    v.yaw_rate = WrapAngle(yaw - it->second) / spec_.step_length;
  return v;
}

const VehicleTypeSpec& SumoSimulation::TypeOf(const std::string& vehicle, const std::string& type) {
  if (own_types_.count(type)) return spec_.vehicle_types.at(type);
  if (const auto it = sumo_types_.find(type); it != sumo_types_.end()) return it->second;
  if (spec_.route_files.empty() && spec_.additional_files.empty())
    throw std::runtime_error("vehicle '" + vehicle + "' has type '" + type +
                             "', which the scenario does not define");
  // A type of the user's route or additional files: its box as SUMO simulates it, its RCS from the
  // scenario (traffic.rcs_dbsm) or its vClass.
  using V = libsumo::Vehicle;
  VehicleTypeSpec t;
  t.length = V::getLength(vehicle);
  t.width = V::getWidth(vehicle);
  t.vclass = V::getVehicleClass(vehicle);
  const auto rcs = spec_.type_rcs.find(type);
  t.rcs_dbsm = rcs != spec_.type_rcs.end() ? rcs->second : VClassRcs(t.vclass);
  return sumo_types_.emplace(type, t).first->second;
}

void SumoSimulation::ApplyDepartures() {
  for (const std::string& id : libsumo::Simulation::getDepartedIDList()) {
    const std::uint64_t index = departures_++;
    if (id == spec_.ego.id) {
      if (spec_.ego_speed.mode == SpeedPolicy::Mode::kSumo) continue;  // as its route file says
      // SUMO needs a positive maximum speed; a parked ego is held by setSpeed(0) each step.
      libsumo::Vehicle::setMaxSpeed(id, std::max(spec_.ego_speed.speed, 0.1));
      if (!spec_.ego.lane_change)
        libsumo::Vehicle::setLaneChangeMode(id, kLaneChangeModeScriptedOnly);
      continue;
    }
    const auto v = std::find_if(spec_.vehicles.begin(), spec_.vehicles.end(),
                                [&](const VehicleSpec& s) { return s.id == id; });
    if (v != spec_.vehicles.end()) {
      if (v->desired_speed) libsumo::Vehicle::setMaxSpeed(id, *v->desired_speed);
      if (!v->lane_change) libsumo::Vehicle::setLaneChangeMode(id, kLaneChangeModeScriptedOnly);
      continue;
    }
    // Flow vehicles are named "<flow id>.<n>": draw their desired speed from the flow's band with
    // a counter-based generator keyed by departure order, which SUMO keeps deterministic.
    const std::string flow_id = id.substr(0, id.rfind('.'));
    const auto f = std::find_if(spec_.flows.begin(), spec_.flows.end(),
                                [&](const FlowSpec& s) { return s.id == flow_id; });
    if (f != spec_.flows.end()) {
      CounterRng rng(spec_.seed, RngPurpose::kSimulation, index, 0);
      libsumo::Vehicle::setMaxSpeed(id, rng.Uniform(f->speed_min, f->speed_max));
    }
  }
}

void SumoSimulation::ApplyActions() {
  const double now = RunTime(libsumo::Simulation::getTime());
  while (next_action_ < spec_.actions.size() && spec_.actions[next_action_].time <= now + 1e-9) {
    const ActionSpec& a = spec_.actions[next_action_++];
    const std::vector<std::string> ids = libsumo::Vehicle::getIDList();
    if (std::find(ids.begin(), ids.end(), a.vehicle) == ids.end())
      throw std::runtime_error("scenario '" + spec_.name + "': action at run time " + Num(a.time) +
                               " s names vehicle '" + a.vehicle +
                               "', which is not on the road at that time");
    if (a.set_speed) libsumo::Vehicle::setMaxSpeed(a.vehicle, *a.set_speed);
    if (a.change_lane) libsumo::Vehicle::changeLane(a.vehicle, *a.change_lane, a.duration);
  }
}

double SumoSimulation::RunTime(double sumo_time) const {
  // SUMO counts whole milliseconds: the difference rounded to them is exact, so a run's times
  // are the same numbers whatever its begin.
  return std::round((sumo_time - spec_.begin) * 1000.0) / 1000.0;
}

std::string SumoSimulation::Clock(double sumo_time) const {
  return "SUMO time " + Num(sumo_time) + " s (run time " + Num(RunTime(sumo_time)) + " s)";
}

void SumoSimulation::SumoStep() {
  try {
    libsumo::Simulation::step();
  } catch (const libsumo::TraCIException&) {
    throw;  // Step's own handlers
  } catch (const libsumo::FatalTraCIError&) {
    throw;
  } catch (const std::exception& e) {
    // SUMO's loader refusing a definition of the user's files when it is first needed (an
    // invalid departLane: a ProcessError, possibly several lines): bad input, in one line naming
    // the files; SUMO's full text stays in sumo.log.
    std::string files;
    for (const std::string& f : spec_.route_files) files += (files.empty() ? "" : ", ") + f;
    for (const std::string& f : spec_.additional_files) files += (files.empty() ? "" : ", ") + f;
    throw std::invalid_argument((files.empty() ? "SUMO" : "SUMO, loading " + files + ",") +
                                " refused a definition at " +
                                Clock(libsumo::Simulation::getTime()) + ": " + OneLine(e.what()) +
                                " (see " + log_path_.string() + ")");
  }
}

bool SumoSimulation::Step() {
  if (closed_) throw std::logic_error("SumoSimulation::Step after Close");
  try {
    std::vector<std::string> ids;
    // Until the ego has departed, steps only advance SUMO: frames start with the ego.
    for (;;) {
      if (step_ >= spec_.StepCount()) {
        if (frame_.step == 0 && spec_.ego_from_routes)
          throw std::runtime_error("ego '" + spec_.ego.id +
                                   "' (ego.from_routes) never entered the network within " +
                                   RunWindow(spec_) +
                                   ": is it a vehicle of the route files that departs in "
                                   "that window? See " +
                                   log_path_.string());
        if (frame_.step == 0)
          throw std::runtime_error(
              "ego '" + spec_.ego.id + "' never entered the network within " + RunWindow(spec_) +
              " (lane " + std::to_string(spec_.ego.lane) + ", position " + Num(spec_.ego.position) +
              " m of route '" + spec_.ego.route +
              "' blocked or invalid, or departure too late; see " + log_path_.string() + ")");
        return false;
      }
      SumoStep();
      ++step_;
      ApplyDepartures();
      ApplyActions();
      ids = libsumo::Vehicle::getIDList();
      std::sort(ids.begin(), ids.end());
      if (std::binary_search(ids.begin(), ids.end(), spec_.ego.id)) break;
      if (frame_.step != 0) {  // the ego reached the end of its route
        ego_left_ = true;
        return false;
      }
    }
    if (spec_.ego_speed.mode == SpeedPolicy::Mode::kFixed)
      libsumo::Vehicle::setSpeed(spec_.ego.id, spec_.ego_speed.speed);
    Frame f;
    f.step = step_;
    f.time = RunTime(libsumo::Simulation::getTime());
    f.vehicles.reserve(ids.size());
    std::map<std::string, double> yaws;
    for (const std::string& id : ids) {
      VehicleState v = ReadVehicle(id);
      yaws[id] = v.box.yaw;
      if (id == spec_.ego.id)
        f.ego = std::move(v);
      else
        f.vehicles.push_back(std::move(v));
    }
    previous_yaw_ = std::move(yaws);
    frame_ = std::move(f);
    return true;
  } catch (const libsumo::TraCIException& e) {
    throw std::runtime_error("SUMO error at " + Clock(libsumo::Simulation::getTime()) + ": " +
                             OneLine(e.what()));
  } catch (const libsumo::FatalTraCIError& e) {
    throw std::runtime_error("SUMO failed at " + Clock(libsumo::Simulation::getTime()) + ": " +
                             OneLine(e.what()));
  }
}

std::vector<SumoSimulation::LaneShape> SumoSimulation::LaneShapes() const {
  std::vector<LaneShape> out;
  for (const std::string& id : libsumo::Lane::getIDList()) {
    if (!id.empty() && id[0] == ':') continue;  // internal junction lanes
    LaneShape l{id, {}, libsumo::Lane::getWidth(id)};
    for (const auto& p : libsumo::Lane::getShape(id).value) l.points.emplace_back(p.x, p.y);
    out.push_back(std::move(l));
  }
  std::sort(out.begin(), out.end(),
            [](const LaneShape& a, const LaneShape& b) { return a.id < b.id; });
  return out;
}

}  // namespace dualgrid::sim
