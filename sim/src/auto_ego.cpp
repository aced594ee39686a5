#include "dualgrid/sim/auto_ego.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>

#include <libsumo/libsumo.h>

#include "auto_ego_run.hpp"
#include "dualgrid/core/text.hpp"
#include "dualgrid/sim/conversions.hpp"

namespace dualgrid::sim {

bool ViewBox::Contains(const Vector2& offset, double yaw) const {
  const double c = std::cos(yaw), s = std::sin(yaw);
  const double along = c * offset.x() + s * offset.y(), across = -s * offset.x() + c * offset.y();
  return along <= ahead && along >= -behind && across <= left && across >= -right;
}

std::string AutoEgoChoice::Reason() const {
  if (with_traffic == 0)
    return "no road vehicle of the route files ever had another vehicle in its grid (" +
           std::to_string(candidates) +
           " candidates): nothing can be scored; chose the one longest in the run (" +
           FormatFixed(in_run_s, 1) + " s)";
  return "the road vehicle of the route files with another vehicle in its grid longest (" +
         FormatFixed(seen_s, 1) + " s of its " + FormatFixed(in_run_s, 1) + " s in the run; " +
         std::to_string(with_traffic) + " of " + std::to_string(candidates) +
         " candidates ever had traffic in their grid)";
}

namespace {

// Vehicle classes that are not road vehicles: never the ego, and never traffic the radar scores.
bool OffRoad(const std::string& vclass) {
  static const std::set<std::string> kOffRoad = {
      "pedestrian", "wheelchair", "tram",   "rail_urban", "rail",    "rail_electric",
      "rail_fast",  "ship",       "subway", "cable_car",  "aircraft"};
  return kOffRoad.count(vclass) > 0;
}

struct Candidate {
  double depart = 0.0;     // [s, SUMO time]
  long present_steps = 0;  // steps in the run (on the road at the step's end)
  long seen_steps = 0;     // of which with another road vehicle in its view box
  std::size_t order = 0;   // departure order
};

struct Seen {
  std::string id;
  Position position;
};

// One step of the first run: every road vehicle's position into a hash of square cells of side
// `cell` [m]; each candidate counts the step when another lies in its view box.
void CountTraffic(const ViewBox& view, double cell, std::map<std::string, Candidate>* candidates) {
  std::vector<Seen> road;
  for (const std::string& id : libsumo::Vehicle::getIDList()) {
    if (OffRoad(libsumo::Vehicle::getVehicleClass(id))) continue;
    const auto p = libsumo::Vehicle::getPosition(id);
    road.push_back({id, Position(p.x, p.y)});
  }
  const auto key = [&](const Position& p) {
    return std::make_pair(static_cast<long>(std::floor(p.x() / cell)),
                          static_cast<long>(std::floor(p.y() / cell)));
  };
  std::map<std::pair<long, long>, std::vector<std::size_t>> cells;
  for (std::size_t i = 0; i < road.size(); ++i) cells[key(road[i].position)].push_back(i);
  for (std::size_t i = 0; i < road.size(); ++i) {
    const auto it = candidates->find(road[i].id);
    if (it == candidates->end()) continue;
    const double yaw = SumoAngleToYaw(libsumo::Vehicle::getAngle(road[i].id));
    const auto [cx, cy] = key(road[i].position);
    bool seen = false;
    for (long dx = -1; dx <= 1 && !seen; ++dx)
      for (long dy = -1; dy <= 1 && !seen; ++dy) {
        const auto c = cells.find({cx + dx, cy + dy});
        if (c == cells.end()) continue;
        for (std::size_t j : c->second)
          seen = seen || (j != i && view.Contains(road[j].position - road[i].position, yaw));
      }
    ++it->second.present_steps;
    it->second.seen_steps += seen ? 1 : 0;
  }
}

}  // namespace

std::optional<AutoEgoChoice> ChooseAutoEgo(const ScenarioSpec& spec,
                                           const std::vector<std::string>& args) {
  libsumo::Simulation::start(args);
  struct Closer {
    ~Closer() {
      try {
        libsumo::Simulation::close();
      } catch (...) {  // after a SUMO error close may throw again; that error is reported
      }
    }
  } closer;
  // The scenario's own vehicles are not the user's: only vehicles of the route files qualify.
  std::set<std::string> own;
  for (const auto& v : spec.vehicles) own.insert(v.id);
  const auto own_flow = [&](const std::string& id) {
    const std::string flow = id.substr(0, id.rfind('.'));
    return std::any_of(spec.flows.begin(), spec.flows.end(),
                       [&](const FlowSpec& f) { return f.id == flow; });
  };
  const ViewBox& view = spec.auto_ego_view;
  // Cells at least as large as the box's reach, so the 3 x 3 cells round a vehicle hold its box.
  const double cell = std::max({view.ahead, view.behind, view.left, view.right, 1.0});
  std::map<std::string, Candidate> seen;
  for (int step = 0; step < spec.StepCount(); ++step) {
    libsumo::Simulation::step();
    const double now = libsumo::Simulation::getTime();
    for (const std::string& id : libsumo::Simulation::getDepartedIDList()) {
      if (own.count(id) || own_flow(id) || OffRoad(libsumo::Vehicle::getVehicleClass(id))) continue;
      seen[id] = {now, 0, 0, seen.size()};
    }
    CountTraffic(view, cell, &seen);
  }
  // Most time with traffic in view; ties: longer in the run, then the earlier departure.
  const auto best = std::max_element(seen.begin(), seen.end(), [](const auto& a, const auto& b) {
    const Candidate &x = a.second, &y = b.second;
    if (x.seen_steps != y.seen_steps) return x.seen_steps < y.seen_steps;
    if (x.present_steps != y.present_steps) return x.present_steps < y.present_steps;
    return x.order > y.order;
  });
  if (best == seen.end()) return std::nullopt;
  AutoEgoChoice choice;
  choice.id = best->first;
  choice.seen_s = best->second.seen_steps * spec.step_length;
  choice.in_run_s = best->second.present_steps * spec.step_length;
  choice.depart_s = best->second.depart;
  choice.candidates = seen.size();
  for (const auto& [id, c] : seen) choice.with_traffic += c.seen_steps > 0 ? 1 : 0;
  return choice;
}

}  // namespace dualgrid::sim
