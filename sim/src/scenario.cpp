#include "dualgrid/sim/scenario.hpp"

#include <cmath>
#include <set>
#include <sstream>

namespace dualgrid::sim {
namespace {

// Sets *error to "<field>: <message>" and returns false; keeps IsValid readable.
bool Fail(std::string* error, const std::string& field, const std::string& message) {
  if (error) *error = field + ": " + message;
  return false;
}

// SUMO refuses ids with these characters (whitespace and XML or list separators).
bool ValidSumoId(const std::string& id) {
  return !id.empty() && id.find_first_of(" \t\n\r|\\'\";,<>&") == std::string::npos;
}
constexpr const char* kIdRule = "must be non-empty without spaces or any of | \\ ' \" ; , < > &";

bool CheckVehicle(const VehicleSpec& v, const std::string& field, const ScenarioSpec& s,
                  std::string* error) {
  if (!ValidSumoId(v.id)) return Fail(error, field + ".id", kIdRule);
  if (!s.vehicle_types.count(v.type))
    return Fail(error, field + ".type", "unknown vehicle type '" + v.type + "'");
  if (!s.routes.count(v.route))
    return Fail(error, field + ".route", "unknown route '" + v.route + "'");
  if (!(v.depart >= 0.0)) return Fail(error, field + ".depart", "must be >= 0 s");
  if (v.lane < 0) return Fail(error, field + ".lane", "must be a lane index >= 0");
  if (!(v.position >= 0.0)) return Fail(error, field + ".position", "must be >= 0 m");
  if (!(v.speed >= kMinTrafficSpeed && v.speed <= kMaxTrafficSpeed))
    return Fail(error, field + ".speed", "must be in [0, 70] m/s");
  if (v.desired_speed && !(*v.desired_speed > 0.0 && *v.desired_speed <= kMaxTrafficSpeed))
    return Fail(error, field + ".desired_speed", "must be in (0, 70] m/s");
  return true;
}

}  // namespace

int ScenarioSpec::StepCount() const {
  return static_cast<int>(std::floor(duration / step_length + 1e-9));
}

double VClassRcs(const std::string& vclass) {
  static const std::map<std::string, double> kRcs = {
      {"passenger", 10.0}, {"private", 10.0},  {"taxi", 10.0},      {"evehicle", 10.0},
      {"emergency", 10.0}, {"delivery", 14.0}, {"truck", 25.0},     {"trailer", 25.0},
      {"bus", 25.0},       {"coach", 25.0},    {"motorcycle", 5.0}, {"moped", 3.0},
      {"bicycle", 0.0}};
  const auto it = kRcs.find(vclass);
  return it == kRcs.end() ? 10.0 : it->second;
}

bool ScenarioSpec::IsValid(std::string* error) const {
  if (network.empty()) return Fail(error, "network", "must name a network");
  if (!(duration > 0.0 && duration <= 3600.0))
    return Fail(error, "duration", "must be in (0, 3600] s");
  if (!(step_length >= 0.001 && step_length <= 1.0))
    return Fail(error, "step_length", "must be in [0.001, 1] s");
  if (std::abs(step_length * 1000.0 - std::round(step_length * 1000.0)) > 1e-6)
    return Fail(error, "step_length", "must be a whole number of milliseconds (SUMO's resolution)");
  if (!(lane_change_duration >= 0.0)) return Fail(error, "lane_change_duration", "must be >= 0 s");
  for (const auto& [name, t] : vehicle_types) {
    const std::string f = "vehicle_types." + name;
    if (!ValidSumoId(name)) return Fail(error, f, std::string("(the type's name) ") + kIdRule);
    if (!(t.length > 0.0 && t.length <= 30.0))
      return Fail(error, f + ".length", "must be in (0, 30] m");
    if (!(t.width > 0.0 && t.width <= 4.0)) return Fail(error, f + ".width", "must be in (0, 4] m");
    if (!(t.max_speed > 0.0 && t.max_speed <= kMaxTrafficSpeed))
      return Fail(error, f + ".max_speed", "must be in (0, 70] m/s");
    if (!(t.accel > 0.0)) return Fail(error, f + ".accel", "must be > 0 m/s^2");
    if (!(t.decel > 0.0)) return Fail(error, f + ".decel", "must be > 0 m/s^2");
    if (!std::isfinite(t.rcs_dbsm)) return Fail(error, f + ".rcs_dbsm", "must be finite");
  }
  for (const auto& [name, edges] : routes) {
    if (!ValidSumoId(name))
      return Fail(error, "routes." + name, std::string("(the route's name) ") + kIdRule);
    if (edges.empty()) return Fail(error, "routes." + name, "must list at least one edge");
  }
  if (!(duration >= step_length))
    return Fail(error, "duration", "must be at least one step_length");
  if (ego_from_routes) {
    if (route_files.empty())
      return Fail(error, "ego.from_routes",
                  "needs SUMO route files (traffic.route_files or sumo_config)");
  } else if (!CheckVehicle(ego, "ego", *this, error)) {
    return false;
  }
  if (!(ego.depart < duration))
    return Fail(error, "ego.depart", "must be before the end (duration)");
  if (!(ego_speed.speed >= 0.0 && ego_speed.speed <= kMaxTrafficSpeed))
    return Fail(error, "ego.speed_policy.speed", "must be in [0, 70] m/s");
  // A parked ego (speed 0) is held by the fixed policy; cruising at 0 would be no policy at all.
  if (ego_speed.speed == 0.0 && ego_speed.mode != SpeedPolicy::Mode::kFixed)
    return Fail(error, "ego.speed_policy.speed", "0 (a parked ego) needs mode: fixed");
  if (ego_speed.speed == 0.0 && ego.speed != 0.0)
    return Fail(error, "ego.speed", "must be 0 for a parked ego (speed_policy.speed 0)");
  std::set<std::string> ids{ego.id};
  for (std::size_t i = 0; i < vehicles.size(); ++i) {
    const std::string f = "traffic.vehicles[" + std::to_string(i) + "]";
    if (!CheckVehicle(vehicles[i], f, *this, error)) return false;
    if (!ids.insert(vehicles[i].id).second)
      return Fail(error, f + ".id", "duplicate vehicle id '" + vehicles[i].id + "'");
  }
  for (std::size_t i = 0; i < flows.size(); ++i) {
    const FlowSpec& fl = flows[i];
    const std::string f = "traffic.flows[" + std::to_string(i) + "]";
    if (!ValidSumoId(fl.id)) return Fail(error, f + ".id", kIdRule);
    if (!ids.insert(fl.id).second) return Fail(error, f + ".id", "duplicate id '" + fl.id + "'");
    if (!vehicle_types.count(fl.type))
      return Fail(error, f + ".type", "unknown vehicle type '" + fl.type + "'");
    if (!routes.count(fl.route))
      return Fail(error, f + ".route", "unknown route '" + fl.route + "'");
    if (!(fl.begin >= 0.0)) return Fail(error, f + ".begin", "must be >= 0 s");
    if (!(fl.end > fl.begin)) return Fail(error, f + ".end", "must be after begin");
    if (!(fl.period > 0.0)) return Fail(error, f + ".period", "must be > 0 s");
    if (!(fl.position >= 0.0)) return Fail(error, f + ".position", "must be >= 0 m");
    if (!(fl.speed_min > 0.0 && fl.speed_min <= fl.speed_max && fl.speed_max <= kMaxTrafficSpeed))
      return Fail(error, f + ".speed_min", "need 0 < speed_min <= speed_max <= 70 m/s");
    const bool lane_ok =
        fl.lane == "random" || fl.lane == "free" || fl.lane == "best" ||
        (!fl.lane.empty() && fl.lane.find_first_not_of("0123456789") == std::string::npos);
    if (!lane_ok)
      return Fail(error, f + ".lane", "must be a lane index, 'random', 'free' or 'best'");
  }
  for (std::size_t i = 0; i < actions.size(); ++i) {
    const ActionSpec& a = actions[i];
    const std::string f = "actions[" + std::to_string(i) + "]";
    // Actions after the end never fire, so a shortened --duration keeps the file valid.
    if (!(a.time >= 0.0)) return Fail(error, f + ".time", "must be >= 0 s");
    if (!ids.count(a.vehicle))
      return Fail(error, f + ".vehicle", "unknown vehicle '" + a.vehicle + "'");
    if (!a.set_speed && !a.change_lane) return Fail(error, f, "needs set_speed or change_lane");
    if (a.set_speed && !(*a.set_speed > 0.0 && *a.set_speed <= kMaxTrafficSpeed))
      return Fail(error, f + ".set_speed", "must be in (0, 70] m/s");
    if (a.change_lane && *a.change_lane < 0) return Fail(error, f + ".change_lane", "must be >= 0");
    if (!(a.duration > 0.0)) return Fail(error, f + ".duration", "must be > 0 s");
  }
  for (std::size_t i = 0; i < guard_rails.size(); ++i) {
    const std::string f = "obstacles.guard_rails[" + std::to_string(i) + "]";
    const auto& pts = guard_rails[i].points;
    if (pts.size() < 2) return Fail(error, f + ".points", "needs at least 2 points");
    for (std::size_t k = 1; k < pts.size(); ++k)
      if (!((pts[k] - pts[k - 1]).norm() > 1e-3))
        return Fail(error, f + ".points",
                    "has a segment of zero length (points " + std::to_string(k - 1) + " and " +
                        std::to_string(k) + " coincide)");
  }
  for (std::size_t i = 0; i < parked.size(); ++i) {
    const OrientedBox& b = parked[i].box;
    const std::string f = "obstacles.parked[" + std::to_string(i) + "]";
    if (!(b.length > 0.0)) return Fail(error, f + ".length", "must be > 0 m");
    if (!(b.width > 0.0)) return Fail(error, f + ".width", "must be > 0 m");
  }
  return true;
}

}  // namespace dualgrid::sim
