#include "dualgrid/scenario/guardrail_case.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "dualgrid/core/text.hpp"
#include "dualgrid/core/types.hpp"

namespace dualgrid::scenario {
namespace {

// The highway network (networks/highway.*): eastbound lanes spread right of y = -2 m, 3.5 m wide,
// so lane 2 (the left lane, beside the median) is centred on y = -3.75 m, lane 1 on -7.25 m,
// lane 0 on -10.75 m; the road runs from x = 0 to 6000 m.
constexpr double kEgoLaneY = -3.75;
constexpr double kFirstEdgeEnd = 1500.0;  // [m] vehicles depart on east_1
constexpr double kEgoFront = 400.0;       // [m] the ego's front bumper along east_1 at t = 0
constexpr double kEgoLength = 4.5, kEgoWidth = 1.8;
constexpr double kRoadEnd = 5900.0;    // [m] the ego must stay on the road
constexpr double kFirstGap = 15.0;     // [m] bumper to bumper, ego -> first passing vehicle
constexpr double kBeyond = 40.0;       // [m] a vehicle has passed when this far clear of the ego
constexpr double kRailMargin = 150.0;  // [m] rail beyond the ego's path at both ends
constexpr double kMaxDrift = 15.0;     // [m] an angled rail ends this far off its pivot's line

struct Vehicle {
  const char* type;
  double length;
};
constexpr Vehicle kCar{"car", 4.5}, kTruck{"truck", 14.0};

// The passing traffic: vehicle i in lane 1 (beside the ego) or 0, every third a truck, its front
// bumper at t = 0, when it is abeam the ego, and how long they all take to pass.
struct Traffic {
  std::vector<Vehicle> vehicles;
  std::vector<double> gaps, abeam, fronts;
  double duration = 0.0;
};

// Throws naming the option when no vehicle would pass or SUMO could not insert them.
void CheckCase(const GuardRailCase& c) {
  const double dv = c.speed - c.ego_speed;
  if (!(std::abs(dv) >= 2.0))
    throw std::invalid_argument(
        "--speed must differ from --ego-speed by at least 2 m/s for vehicles to pass the ego, "
        "got " +
        FormatFixed(c.speed, 2) + " m/s with an ego at " + FormatFixed(c.ego_speed, 2) + " m/s");
  // SUMO inserts vehicles of one lane only about one second of travel plus a length apart.
  const double min_spacing = 18.0 + c.speed;
  if (!(c.spacing >= min_spacing))
    throw std::invalid_argument("--spacing must be >= " + FormatFixed(min_spacing, 1) +
                                " m for guardrail traffic (18 m + speed x 1 s), got " +
                                FormatFixed(c.spacing, 1) + " m");
  if (!(c.offset >= 0.5 * kEgoWidth + 0.3))
    throw std::invalid_argument("--offset must be >= 1.2 m (the ego's half width and 0.3 m), got " +
                                FormatFixed(c.offset, 2) + " m");
}

Traffic PlaceTraffic(const GuardRailCase& c) {
  const double dv = c.speed - c.ego_speed;
  Traffic t;
  auto& vehicles = t.vehicles;
  auto& gaps = t.gaps;
  auto& abeam = t.abeam;
  auto& fronts = t.fronts;
  double& duration = t.duration;
  // Vehicle i: lane 1 (beside the ego) or 0, every third a truck; a gap of kFirstGap + i s / 2 to
  // the ego (behind it when faster, ahead when slower), so one lane's vehicles are s apart.
  for (int i = 0; i < c.count; ++i) {
    vehicles.push_back(i % 3 == 2 ? kTruck : kCar);
    gaps.push_back(kFirstGap + i * 0.5 * c.spacing);
    // Passed: from gap_i behind the ego to kBeyond clear ahead of it (or the reverse).
    duration =
        std::max(duration, (gaps[i] + kEgoLength + vehicles[i].length + kBeyond) / std::abs(dv));
    abeam.push_back((gaps[i] + 0.5 * (kEgoLength + vehicles[i].length)) / std::abs(dv));
  }
  duration = std::ceil(duration + 1.0);
  for (int i = 0; i < c.count; ++i)
    fronts.push_back(dv > 0.0 ? kEgoFront - kEgoLength - gaps[i]
                              : kEgoFront + gaps[i] + vehicles[i].length);
  const double last_front = *std::max_element(fronts.begin(), fronts.end());
  if (kEgoFront + c.ego_speed * duration > kRoadEnd || last_front >= kFirstEdgeEnd ||
      last_front + c.speed * duration > kRoadEnd)
    throw std::invalid_argument(
        "the vehicles would need " + FormatFixed(duration, 0) +
        " s to pass, more than the 6 km highway allows at these speeds and gaps; raise the "
        "difference between --speed and --ego-speed, or lower --count or --spacing");

  return t;
}

// The rail's two ends: through the point `offset` to the left of the ego's centre at half the
// run, turned by rail_angle; it ends where it would come closer to the ego's lane centre than
// min(offset, 2 m) (a rail never enters the ego's lane).
struct Rail {
  Position a, b, pivot;
};
Rail PlaceRail(const GuardRailCase& c, double duration) {
  const double alpha = DegToRad(c.rail_angle);
  const double x0 = kEgoFront - 0.5 * kEgoLength;  // ego centre at t = 0
  const double pivot_x = x0 + 0.5 * c.ego_speed * duration;
  const double pivot_y = kEgoLaneY + c.offset;
  double u_lo = (x0 - kRailMargin - pivot_x) / std::cos(alpha);
  double u_hi = (x0 + c.ego_speed * duration + kRailMargin - pivot_x) / std::cos(alpha);
  const double clearance = std::min(c.offset, 2.0);
  if (alpha > 0.0) u_lo = std::max(u_lo, (clearance - c.offset) / std::sin(alpha));
  if (alpha < 0.0) u_hi = std::min(u_hi, (clearance - c.offset) / std::sin(alpha));
  // ... and where it has turned kMaxDrift away from the road (beyond, it mirrors nothing the
  // radars would see, and it would cross the other carriageway).
  if (alpha > 0.0) u_hi = std::min(u_hi, kMaxDrift / std::sin(alpha));
  if (alpha < 0.0) u_lo = std::max(u_lo, kMaxDrift / std::sin(alpha));
  if (!(u_hi - u_lo >= 10.0))
    throw std::invalid_argument("--rail-angle " + FormatFixed(c.rail_angle, 1) +
                                " deg leaves less than 10 m of rail beside the ego's lane");
  const Vector2 dir = UnitVector(alpha);
  const Position pivot(pivot_x, pivot_y);
  return {pivot + u_lo * dir, pivot + u_hi * dir, pivot};
}

}  // namespace

std::string GuardRailScenario(const GuardRailCase& c) {
  CheckCase(c);
  const double dv = c.speed - c.ego_speed;
  const Traffic t = PlaceTraffic(c);
  const double duration = t.duration;
  const Rail rail = PlaceRail(c, duration);
  const Position &a = rail.a, &b = rail.b;
  std::ostringstream os;
  const char* side = dv > 0.0 ? "overtake the ego" : "are overtaken by the ego";
  os << "# Multipath stress case (guardrail), generated by:\n"
     << "#   dualgrid tangential --kind guardrail --offset " << c.offset << " --rail-angle "
     << c.rail_angle << " --count " << c.count << " --ego-speed " << c.ego_speed << " --speed "
     << c.speed << " --spacing " << c.spacing << " --seed " << c.seed << "\n"
     << "# The ego drives in the left lane (y = " << kEgoLaneY << ") at " << c.ego_speed
     << " m/s beside a guard rail " << c.offset << " m to its left,\n# turned by " << c.rail_angle
     << " deg about (" << FormatFixed(rail.pivot.x(), 1) << ", " << FormatFixed(rail.pivot.y(), 2)
     << ");\n# cars and trucks " << side << " in the two lanes to its right at " << c.speed
     << " m/s. The rail is the only obstacle: the corner radars see\n# the vehicles' mirror "
        "images beyond it (docs/radar.md, \"Multipath\"; run with --set sensors.multipath=on).\n"
     << "# Vehicle i is abeam the ego at t = ";
  for (int i = 0; i < c.count; ++i) os << (i ? ", " : "") << FormatFixed(t.abeam[i], 1);
  os << " s.\n"
     << "name: guardrail\n"
     << "description: vehicles pass the ego on the side away from a guard rail (multipath)\n"
     << "network: highway\nduration: " << FormatFixed(duration, 1)
     << "\nstep_length: 0.05\nseed: " << c.seed
     << "\n\n"
     // Passing on the right is allowed (SUMO's drivers otherwise keep behind the ego).
     << "vehicle_types:\n  car: {length: 4.5, width: 1.8, max_speed: 50.0, rcs_dbsm: 10.0, "
        "overtake_right: true}\n"
     << "  truck: {length: 14.0, width: 2.55, max_speed: 40.0, rcs_dbsm: 25.0, vclass: truck, "
        "overtake_right: true}\n\n"
     << "routes:\n  east: [east_1, east_2, east_3]\n\n"
     << "ego: {type: car, route: east, lane: 2, position: " << kEgoFront
     << ", speed: " << c.ego_speed << ", speed_policy: {mode: fixed, speed: " << c.ego_speed
     << "}}\n\n"
     << "traffic:\n  vehicles:\n";
  for (int i = 0; i < c.count; ++i) {
    os << "    - {id: pass_" << (i + 1) << ", type: " << t.vehicles[i].type
       << ", route: east, lane: " << (i % 2 ? 0 : 1)
       << ", position: " << FormatFixed(t.fronts[i], 2) << ", speed: " << c.speed
       << ", desired_speed: " << c.speed << ", lane_change: false}\n";
  }
  os << "\nobstacles:\n  guard_rails:\n    - {id: rail, points: [[" << FormatFixed(a.x(), 3) << ", "
     << FormatFixed(a.y(), 3) << "], [" << FormatFixed(b.x(), 3) << ", " << FormatFixed(b.y(), 3)
     << "]]}\n"
     << "\nevaluation:\n  focus_object: pass_1\n  snapshot_times: [";
  for (int i = 0; i < c.count; ++i)
    if (t.abeam[i] <= duration) os << (i ? ", " : "") << FormatFixed(t.abeam[i], 2);
  os << "]\n";
  return os.str();
}

}  // namespace dualgrid::scenario
