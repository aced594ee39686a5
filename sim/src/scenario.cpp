#include "dualgrid/sim/scenario.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <set>
#include <sstream>

#include "dualgrid/core/limits.hpp"
#include "dualgrid/core/text.hpp"
#include "dualgrid/core/validation.hpp"
#include "dualgrid/sim/vehicle_ranges.hpp"

namespace dualgrid::sim {
namespace {

// SUMO refuses ids with these characters (whitespace and XML or list separators).
bool ValidSumoId(const std::string& id) {
  return !id.empty() && id.find_first_of(" \t\n\r|\\'\";,<>&") == std::string::npos;
}
constexpr const char* kIdRule = "non-empty, without spaces or any of | \\ ' \" ; , < > &";

// A name's text for messages.
std::string Quoted(const std::string& s) { return "'" + s + "'"; }

void CheckVehicle(FieldCheck& c, const VehicleSpec& v, const std::string& field,
                  const ScenarioSpec& s) {
  c.Expect(ValidSumoId(v.id), field + ".id", Quoted(v.id), kIdRule);
  c.Expect(s.vehicle_types.count(v.type) > 0, field + ".type", Quoted(v.type),
           "a vehicle type of the scenario");
  c.Expect(s.routes.count(v.route) > 0, field + ".route", Quoted(v.route),
           "a route of the scenario");
  c.NonNegative(field + ".depart", v.depart, "s");
  c.AtLeast(field + ".lane", v.lane, 0);
  c.NonNegative(field + ".position", v.position, "m");
  c.InRange(field + ".speed", v.speed, kMinTrafficSpeed, kMaxTrafficSpeed, Interval::kClosed,
            "m/s");
  if (v.desired_speed)
    c.InRange(field + ".desired_speed", *v.desired_speed, 0.0, kMaxTrafficSpeed,
              Interval::kLeftOpen, "m/s");
}

// A scenario vehicle type's number `v` in the range of SUMO's vType attribute `sumo_attribute`.
void TypeNumber(FieldCheck& c, const std::string& field, const char* sumo_attribute, double v) {
  const std::optional<NumberRange> r = VTypeAttributeRange(sumo_attribute);
  assert(r);
  c.InRange(field, v, r->lo, r->hi, r->ends, r->unit);
}

// The ego of the user's files must depart within the run (SUMO skips vehicles that depart before
// its begin; one departing after the end never enters).
void CheckEgoDeparture(FieldCheck& c, const ScenarioSpec& s) {
  if (!s.ego_departure) return;
  const std::optional<double> t = s.ego_departure->At(s.begin);
  const std::string window = "SUMO time [" + FormatShort(s.begin) + ", " +
                             FormatShort(s.begin + s.duration) + "] s (begin + duration)";
  if (!t) {
    c.Expect(false, "ego.from_routes", Quoted(s.ego.id),
             "a member its flow creates when SUMO begins at " + FormatShort(s.begin) +
                 " s (SUMO time): the flow ends before it departs");
    return;
  }
  c.Expect(*t >= s.begin && *t < s.begin + s.duration, "ego.from_routes", Quoted(s.ego.id),
           "a vehicle departing in the run, " + window + ", but it departs at SUMO time " +
               FormatShort(*t) + " s" +
               (*t < s.begin ? " and SUMO skips vehicles that depart before the begin"
                             : ": set begin (or --begin) or a longer duration"));
}

// The run's window on SUMO's clock: begin (its source named), duration, the configuration's end.
void CheckTimes(FieldCheck& c, const ScenarioSpec& s) {
  const std::string begin_key = s.begin_source == "command line"  ? "--begin"
                                : s.begin_source == "sumo_config" ? "sumo_config <begin>"
                                                                  : "begin";
  c.InRange(begin_key, s.begin, 0.0, kMaxBegin, Interval::kClosed, "s (SUMO time)");
  if (s.config_end)
    c.Expect(s.begin < *s.config_end, begin_key, s.begin,
             "< the configuration's end = " + FormatShort(*s.config_end) +
                 " s (SUMO time): a run that begins after SUMO's end");
  c.InRange("duration", s.duration, 0.0, kMaxDuration, Interval::kLeftOpen, "s (run time)");
  CheckEgoDeparture(c, s);
}

}  // namespace

std::optional<double> FileDeparture::At(double begin) const {
  if (!period) return depart;
  const double t = std::max(depart, begin) + static_cast<double>(member) * *period;
  if (flow_end && !(t < *flow_end)) return std::nullopt;
  return t;
}

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
  FieldCheck c;
  c.Expect(!network.empty(), "network", "''", "the name or path of a network");
  c.Expect(seed <= kMaxSeed, "seed", std::to_string(seed),
           "a whole number in [0, " + std::to_string(kMaxSeed) + "] (as --seed)");
  CheckTimes(c, *this);
  c.InRange("step_length", step_length, 0.001, 1.0, Interval::kClosed, "s");
  c.Expect(std::abs(step_length * 1000.0 - std::round(step_length * 1000.0)) <= 1e-6, "step_length",
           step_length, "a whole number of milliseconds (SUMO's resolution)");
  c.NonNegative("lane_change_duration", lane_change_duration, "s");
  for (const auto& [name, t] : vehicle_types) {
    const std::string f = "vehicle_types." + name;
    c.Expect(ValidSumoId(name), f, Quoted(name), std::string("a type name ") + kIdRule);
    // The same rows as the vTypes of the user's SUMO files (vehicle_ranges.hpp).
    TypeNumber(c, f + ".length", "length", t.length);
    TypeNumber(c, f + ".width", "width", t.width);
    TypeNumber(c, f + ".max_speed", "maxSpeed", t.max_speed);
    TypeNumber(c, f + ".accel", "accel", t.accel);
    TypeNumber(c, f + ".decel", "decel", t.decel);
    c.Expect(IsSumoVehicleClass(t.vclass), f + ".vclass", Quoted(t.vclass),
             "a SUMO vehicle class, " + SumoVehicleClassList());
    c.InRange(f + ".rcs_dbsm", t.rcs_dbsm, kMinRcsDbsm, kMaxRcsDbsm, Interval::kClosed, "dBsm");
  }
  for (const auto& [type, rcs] : type_rcs)
    c.InRange("traffic.rcs_dbsm." + type, rcs, kMinRcsDbsm, kMaxRcsDbsm, Interval::kClosed, "dBsm");
  for (const auto& [name, edges] : routes) {
    c.Expect(ValidSumoId(name), "routes." + name, Quoted(name),
             std::string("a route name ") + kIdRule);
    c.Expect(!edges.empty(), "routes." + name, "[]", "at least one edge");
  }
  c.Expect(duration >= step_length, "duration", duration,
           ">= step_length = " + FormatShort(step_length) + " s (at least one step)");
  if (ego_from_routes)
    c.Expect(!route_files.empty() || !additional_files.empty() || random_trips, "ego.from_routes",
             Quoted(ego.id),
             "SUMO route or additional files to take it from (traffic.route_files, sumo_config "
             "or traffic.random_trips)");
  else
    CheckVehicle(c, ego, "ego", *this);
  c.Expect(ego.depart < duration, "ego.depart", ego.depart,
           "< duration = " + FormatShort(duration) + " s (run time: a departure within the run)");
  c.InRange("ego.speed_policy.speed", ego_speed.speed, 0.0, kMaxTrafficSpeed, Interval::kClosed,
            "m/s");
  // A parked ego (speed 0) is held by the fixed policy; cruising at 0 would be no policy at all.
  c.Expect(!(ego_speed.speed == 0.0 && ego_speed.mode != SpeedPolicy::Mode::kFixed),
           "ego.speed_policy.speed", 0.0, "> 0, or mode: fixed for a parked ego");
  c.Expect(!(ego_speed.speed == 0.0 && ego.speed != 0.0), "ego.speed", ego.speed,
           "0 for a parked ego (speed_policy.speed 0)");
  std::set<std::string> ids{ego.id};
  for (std::size_t i = 0; i < vehicles.size(); ++i) {
    const std::string f = Indexed("traffic.vehicles", i);
    CheckVehicle(c, vehicles[i], f, *this);
    c.Expect(ids.insert(vehicles[i].id).second, f + ".id", Quoted(vehicles[i].id),
             "an id no other vehicle has");
  }
  for (std::size_t i = 0; i < flows.size(); ++i) {
    const FlowSpec& fl = flows[i];
    const std::string f = Indexed("traffic.flows", i);
    c.Expect(ValidSumoId(fl.id), f + ".id", Quoted(fl.id), kIdRule);
    c.Expect(ids.insert(fl.id).second, f + ".id", Quoted(fl.id), "an id no other vehicle has");
    c.Expect(vehicle_types.count(fl.type) > 0, f + ".type", Quoted(fl.type),
             "a vehicle type of the scenario");
    c.Expect(routes.count(fl.route) > 0, f + ".route", Quoted(fl.route), "a route of the scenario");
    c.NonNegative(f + ".begin", fl.begin, "s");
    c.Expect(fl.end > fl.begin, f + ".end", fl.end, "> begin = " + FormatShort(fl.begin) + " s");
    c.Positive(f + ".period", fl.period, "s");
    c.NonNegative(f + ".position", fl.position, "m");
    c.Expect(fl.speed_min > 0.0 && fl.speed_min <= fl.speed_max && fl.speed_max <= kMaxTrafficSpeed,
             f + ".speed_min", fl.speed_min,
             "0 < speed_min <= speed_max = " + FormatShort(fl.speed_max) + " <= 70 m/s");
    const bool lane_ok =
        fl.lane == "random" || fl.lane == "free" || fl.lane == "best" ||
        (!fl.lane.empty() && fl.lane.find_first_not_of("0123456789") == std::string::npos);
    c.Expect(lane_ok, f + ".lane", Quoted(fl.lane), "a lane index, 'random', 'free' or 'best'");
  }
  for (std::size_t i = 0; i < actions.size(); ++i) {
    const ActionSpec& a = actions[i];
    const std::string f = Indexed("actions", i);
    // Actions after the end never fire, so a shortened --duration keeps the file valid.
    c.NonNegative(f + ".time", a.time, "s");
    c.Expect(ids.count(a.vehicle) > 0, f + ".vehicle", Quoted(a.vehicle),
             "a vehicle of the scenario");
    c.Expect(a.set_speed || a.change_lane, f, "{}", "set_speed or change_lane");
    if (a.set_speed)
      c.InRange(f + ".set_speed", *a.set_speed, 0.0, kMaxTrafficSpeed, Interval::kLeftOpen, "m/s");
    if (a.change_lane) c.AtLeast(f + ".change_lane", *a.change_lane, 0);
    c.Positive(f + ".duration", a.duration, "s");
  }
  for (std::size_t i = 0; i < guard_rails.size(); ++i) {
    const std::string f = Indexed("obstacles.guard_rails", i);
    const auto& pts = guard_rails[i].points;
    c.Expect(pts.size() >= 2, f + ".points", std::to_string(pts.size()) + " points",
             "at least 2 points");
    c.InRange(f + ".rcs_dbsm_per_metre", guard_rails[i].rcs_dbsm_per_metre, kMinRcsDbsm,
              kMaxRcsDbsm, Interval::kClosed, "dBsm per metre");
    for (std::size_t k = 1; k < pts.size(); ++k)
      c.Expect((pts[k] - pts[k - 1]).norm() > 1e-3, Indexed(f + ".points", k),
               FormatTuple({pts[k].x(), pts[k].y()}),
               "a point other than points[" + std::to_string(k - 1) + "] (no zero-length segment)");
  }
  for (std::size_t i = 0; i < parked.size(); ++i) {
    const OrientedBox& b = parked[i].box;
    const std::string f = Indexed("obstacles.parked", i);
    c.Positive(f + ".length", b.length, "m");
    c.Positive(f + ".width", b.width, "m");
    c.InRange(f + ".rcs_dbsm", parked[i].rcs_dbsm, kMinRcsDbsm, kMaxRcsDbsm, Interval::kClosed,
              "dBsm");
  }
  return c.Done(error);
}

}  // namespace dualgrid::sim
