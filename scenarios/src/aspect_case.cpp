#include "dualgrid/scenario/aspect_case.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "dualgrid/core/text.hpp"
#include "dualgrid/core/types.hpp"
#include "dualgrid/radar_model/sensor_params.hpp"

namespace dualgrid::scenario {
namespace {

constexpr double kEgoLength = 4.5, kEgoWidth = 1.8;
constexpr double kStep = 0.05;      // [s] step length of the generated scenario
constexpr double kFirstTime = 6.0;  // [s] reference time of the first target
constexpr double kLeadTime = 8.0;   // [s] a target drives this long before its reference time
constexpr double kTailTime = 4.0;   // [s] simulated after the last reference time
constexpr double kEgoStartX = 0.0;  // [m] ego centre at t = 0 (road from x = -100)
// Frames in the grid a target needs: evaluation.min_frames_in_grid (20) plus half a second, so
// that a target that is scored has also been in view for a while.
constexpr int kMinFrames = 30;

struct TargetType {
  const char* name;
  double length, width, rcs_dbsm;
  const char* vclass;
};
// Cyclist: a 1.8 m x 0.6 m box of 0 dBsm (bicycle with rider: roughly -5..5 dBsm in published
// 77 GHz measurements; the middle taken).
constexpr TargetType kTypes[] = {{"car", 4.5, 1.8, 10.0, "passenger"},
                                 {"truck", 12.0, 2.55, 20.0, "truck"},
                                 {"cyclist", 1.8, 0.6, 0.0, "bicycle"}};

struct Target {
  double t_ref, depart, pos0, before, after;
  Position p;
  int road = 0;  // index into roads (targets with the same reference point share one)
  int frames_in_grid = 0;
};
struct Road {
  Position p;
  double before = 0.0, after = 0.0;
};

// The case's geometry: the sensor, the targets and their roads.
struct Geometry {
  AspectCase c;
  const TargetType* type = nullptr;
  const radar::SensorParams* sensor = nullptr;
  std::vector<radar::SensorParams> rig;
  double theta = 0.0, psi = 0.0, duration = 0.0, half_l = 0.0;
  Vector2 los, dir;
  std::vector<Road> roads;
  std::vector<Target> targets;
  std::string widened;  // the header's note when the grid was widened

  // Frames with the centre inside the world-aligned 200 m x `width` grid around the ego (half a
  // cell of margin for the grid's snapping to whole cells).
  int FramesIn(const Position& p, double t_ref, double depart, double width) const {
    int frames = 0;
    for (double time = depart; time <= duration + 1e-9; time += kStep) {
      const Position centre = p + c.speed * (time - t_ref) * dir;
      const double ex = kEgoStartX + c.ego_speed * time;
      frames += std::abs(centre.x() - ex) < 99.5 && std::abs(centre.y()) < 0.5 * width - 0.5;
    }
    return frames;
  }
  // Every target is scored and inside the grid at its reference point, where the aspect angle is
  // the asked one.
  bool Fits(double width) const {
    for (const auto& t : targets)
      if (FramesIn(t.p, t.t_ref, t.depart, width) < kMinFrames ||
          std::abs(t.p.y()) > 0.5 * width - 0.5 - half_l)
        return false;
    return true;
  }
  // The smallest multiple of 5 m (up to 400 m) that fits; 0 when none does.
  double NeededWidth() const {
    for (double w = 5.0 * std::ceil(c.grid_width / 5.0); w <= 400.0; w += 5.0)
      if (Fits(w)) return w;
    return 0.0;
  }
};

// The target type and the sensor, checked.
void Resolve(Geometry* g) {
  const AspectCase& c = g->c;
  for (const auto& t : kTypes)
    if (c.target == t.name) g->type = &t;
  if (!g->type) throw std::invalid_argument("--target: expected car, truck or cyclist");
  g->rig = radar::DefaultRig(kEgoLength, kEgoWidth);
  std::string names;
  for (const auto& s : g->rig) {
    names += (names.empty() ? "" : ", ") + s.name;
    if (s.name == c.sensor) g->sensor = &s;
  }
  if (!g->sensor)
    throw std::invalid_argument("--sensor: expected one of " + names + ", got '" + c.sensor + "'");
  if (c.range <= g->sensor->min_range + 1.0 || c.range >= g->sensor->max_range - 5.0)
    throw std::invalid_argument(
        "--range: the " + c.sensor + " radar sees " + FormatFixed(g->sensor->min_range, 1) + "-" +
        FormatFixed(g->sensor->max_range, 0) + " m; expected a range within (" +
        FormatFixed(g->sensor->min_range + 1.0, 1) + ", " +
        FormatFixed(g->sensor->max_range - 5.0, 0) + ") m, got " + FormatFixed(c.range, 1));
}

// Each target's reference point and departure, and the roads through them.
void PlaceTargets(Geometry* g) {
  const AspectCase& c = g->c;
  g->theta = DegToRad(c.angle_deg);
  g->psi = g->sensor->mount.yaw;  // ego yaw 0: world yaw of the boresight
  g->los = UnitVector(g->psi);
  // Velocity direction: the line of sight turned by theta (counter-clockwise).
  g->dir = UnitVector(g->psi + g->theta);
  g->duration = kFirstTime + (c.count - 1) * c.interval + kTailTime;
  g->half_l = 0.5 * g->type->length;
  auto& roads = g->roads;
  for (int k = 0; k < c.count; ++k) {
    Target t;
    t.t_ref = kFirstTime + k * c.interval;
    const Position sensor_at =
        Position(kEgoStartX + c.ego_speed * t.t_ref, 0.0) + g->sensor->mount.position;
    t.p = sensor_at + c.range * g->los;
    t.depart = std::max(0.0, std::round((t.t_ref - kLeadTime) / kStep) * kStep);
    t.pos0 = g->type->length + 0.1;  // front bumper on the edge at departure
    // Centre at p at t_ref: the edge starts this far before p.
    t.before = t.pos0 + c.speed * (t.t_ref - t.depart) - g->half_l;
    t.after = c.speed * (g->duration - t.t_ref) + 50.0;
    // A parked ego puts every target through the same point: one road for them all.
    t.road = -1;
    for (std::size_t r = 0; r < roads.size(); ++r)
      if ((roads[r].p - t.p).norm() < 1e-3) t.road = static_cast<int>(r);
    if (t.road < 0) {
      t.road = static_cast<int>(roads.size());
      roads.push_back({t.p, 0.0, 0.0});
    }
    roads[t.road].before = std::max(roads[t.road].before, t.before);
    roads[t.road].after = std::max(roads[t.road].after, t.after);
    t.frames_in_grid = g->FramesIn(t.p, t.t_ref, t.depart, c.grid_width);
    g->targets.push_back(t);
  }
}

// Widens the grid when asked and needed; throws naming what to change when the targets would
// still not be scored.
void FitGrid(Geometry* g) {
  AspectCase& c = g->c;
  if (!g->Fits(c.grid_width) && c.auto_grid_width) {
    if (const double need = g->NeededWidth(); need > 0.0) {
      g->widened = "# The grid is widened from the paper's " + FormatFixed(c.grid_width, 0) +
                   " m to " + FormatFixed(need, 0) +
                   " m (filter.width_y) so that every target is scored.\n";
      c.grid_width = need;
      for (auto& t : g->targets) t.frames_in_grid = g->FramesIn(t.p, t.t_ref, t.depart, need);
    }
  }
  if (g->Fits(c.grid_width)) return;
  const double need = g->NeededWidth();
  const Target& t = g->targets.front();
  std::string why =
      std::abs(t.p.y()) > 0.5 * c.grid_width - 0.5 - g->half_l
          ? "its reference point, " + FormatFixed(c.range, 1) + " m on the " + c.sensor +
                " radar's boresight, lies " + FormatFixed(std::abs(t.p.y()), 1) +
                " m to the side of the ego, outside the " + FormatFixed(c.grid_width, 0) +
                " m wide grid"
          : "it would be in the " + FormatFixed(c.grid_width, 0) + " m wide grid for " +
                std::to_string(g->FramesIn(t.p, t.t_ref, t.depart, c.grid_width)) +
                " frames, fewer than the " + std::to_string(kMinFrames) + " a scored target needs";
  throw std::invalid_argument(
      "the targets would not be scored: " + why + "; " +
      (need > 0.0 ? "use --grid-width " + FormatFixed(need, 0) + ", " : "") +
      "a lower --speed or a shorter --range");
}

// The network: the ego's road along world x, and one straight road per target through its
// reference point; roads cross without junctions (SUMO keeps them independent).
void NetworkXml(const Geometry& g, AspectCaseFiles* f) {
  const AspectCase& c = g.c;
  const auto& roads = g.roads;
  const Vector2& dir = g.dir;
  const double duration = g.duration;
  const double road_end = kEgoStartX + c.ego_speed * duration + 400.0;
  std::ostringstream nod, edg;
  nod << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<!-- generated by dualgrid tangential, "
         "kind aspect -->\n<nodes>\n"
      << "    <node id=\"ego_w\" x=\"-100.00\" y=\"0.00\" type=\"priority\"/>\n"
      << "    <node id=\"ego_e\" x=\"" << FormatFixed(road_end, 2)
      << "\" y=\"0.00\" type=\"priority\"/>\n";
  edg << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<edges>\n"
      << "    <edge id=\"ego_road\" from=\"ego_w\" to=\"ego_e\" numLanes=\"1\" speed=\"45\" "
         "width=\"3.5\" spreadType=\"center\"/>\n";
  for (std::size_t k = 0; k < roads.size(); ++k) {
    const Position a = roads[k].p - roads[k].before * dir, b = roads[k].p + roads[k].after * dir;
    std::string id = "t";
    id += std::to_string(k + 1);
    nod << "    <node id=\"" << id << "_a\" x=\"" << FormatFixed(a.x(), 3) << "\" y=\""
        << FormatFixed(a.y(), 3) << "\" type=\"priority\"/>\n"
        << "    <node id=\"" << id << "_b\" x=\"" << FormatFixed(b.x(), 3) << "\" y=\""
        << FormatFixed(b.y(), 3) << "\" type=\"priority\"/>\n";
    edg << "    <edge id=\"" << id << "\" from=\"" << id << "_a\" to=\"" << id
        << "_b\" numLanes=\"1\" speed=\"45\" width=\"3.5\" spreadType=\"center\"/>\n";
  }
  nod << "</nodes>\n";
  edg << "</edges>\n";
  f->nodes = nod.str();
  f->edges = edg.str();
}

// The scenario YAML, headed by the command and the geometry.
std::string ScenarioYaml(const Geometry& g, const std::string& stem) {
  const AspectCase& c = g.c;
  const auto& targets = g.targets;
  const auto& roads = g.roads;
  const TargetType* type = g.type;
  const double theta = g.theta, psi = g.psi, duration = g.duration, half_l = g.half_l;
  const double ego_front = 100.0 + kEgoStartX + 0.5 * kEgoLength;  // along ego_road (from -100)
  std::ostringstream y;
  y << "# Aspect-angle stress case, generated by:\n#   dualgrid tangential --kind aspect --sensor "
    << c.sensor << " --angle " << c.angle_deg << " --range " << c.range << " --speed " << c.speed
    << " --ego-speed " << c.ego_speed << " --target " << c.target << " --count " << c.count
    << " --interval " << c.interval << " --grid-width " << c.grid_width << " --seed " << c.seed
    << "\n# Geometry (docs/stress.md): at its reference time t_k each target's centre is "
    << c.range << " m from the " << c.sensor << " radar on its boresight (world yaw "
    << FormatFixed(RadToDeg(psi), 1) << " deg),\n# moving at " << c.speed
    << " m/s over ground at aspect angle " << c.angle_deg
    << " deg to the line of sight (0 = receding along it, 90 = across it, 180 = approaching):\n"
    << "# compensated radial speed there v cos(theta) = "
    << FormatFixed(c.speed * std::cos(theta), 2) << " m/s. Ego: a " << kEgoLength
    << " m car on a straight road along world x at " << c.ego_speed << " m/s"
    << (c.ego_speed == 0.0 ? " (parked)" : "") << ".\n";
  for (std::size_t k = 0; k < targets.size(); ++k)
    y << "#   target_" << k + 1 << ": t_k = " << FormatFixed(targets[k].t_ref, 2) << " s at ("
      << FormatFixed(targets[k].p.x(), 2) << ", " << FormatFixed(targets[k].p.y(), 2)
      << "), departs " << FormatFixed(targets[k].depart, 2) << " s, " << targets[k].frames_in_grid
      << " frames in the grid\n";
  y << g.widened << "# Network: " << stem << ".net.xml, built by netconvert from " << stem
    << ".nod.xml/.edg.xml (roads cross without junctions).\n"
    << "name: aspect_" << c.sensor << "_" << FormatFixed(c.angle_deg, 0) << "\n"
    << "description: targets at aspect angle " << c.angle_deg << " deg to the " << c.sensor
    << " radar's line of sight\n"
    << "network: " << stem << ".net.xml\n"
    << "duration: " << FormatFixed(duration, 2) << "\nstep_length: " << kStep
    << "\nseed: " << c.seed
    << "\n\nvehicle_types:\n  car: {length: 4.5, width: 1.8, max_speed: 50.0, rcs_dbsm: 10.0}\n";
  if (c.target != "car")
    y << "  " << type->name << ": {length: " << type->length << ", width: " << type->width
      << ", max_speed: 50.0, rcs_dbsm: " << type->rcs_dbsm << ", vclass: " << type->vclass << "}\n";
  y << "\nroutes:\n  ego: [ego_road]\n";
  for (std::size_t k = 0; k < roads.size(); ++k) y << "  t" << k + 1 << ": [t" << k + 1 << "]\n";
  y << "\nego: {type: car, route: ego, lane: 0, position: " << FormatFixed(ego_front, 2)
    << ", speed: " << c.ego_speed << ", speed_policy: {mode: fixed, speed: " << c.ego_speed
    << "}}\n\ntraffic:\n  vehicles:\n";
  for (std::size_t k = 0; k < targets.size(); ++k)
    y << "    - {id: target_" << k + 1 << ", type: " << type->name << ", route: t"
      << targets[k].road + 1 << ", lane: 0, depart: " << FormatFixed(targets[k].depart, 2)
      << ", position: "
      << FormatFixed(roads[targets[k].road].before + half_l -
                         c.speed * (targets[k].t_ref - targets[k].depart),
                     2)
      << ", speed: " << c.speed << ", desired_speed: " << c.speed << ", lane_change: false}\n";
  if (c.grid_width != 25.0) y << "\nfilter: {width_y: " << c.grid_width << "}\n";
  y << "\nevaluation:\n  focus_object: target_1\n  snapshot_times: [";
  for (std::size_t k = 0; k < targets.size(); ++k)
    y << (k ? ", " : "") << FormatFixed(targets[k].t_ref, 2);
  y << "]\n";
  return y.str();
}

}  // namespace

AspectCaseFiles MakeAspectCase(const AspectCase& asked, const std::string& stem) {
  Geometry g;
  g.c = asked;  // the grid width may be widened
  Resolve(&g);
  PlaceTargets(&g);
  FitGrid(&g);
  AspectCaseFiles f;
  NetworkXml(g, &f);
  f.scenario = ScenarioYaml(g, stem);
  f.summary = "aspect " + FormatFixed(g.c.angle_deg, 1) + " deg to the " + g.c.sensor +
              " radar at " + FormatFixed(g.c.range, 1) +
              " m, v cos(theta) = " + FormatFixed(g.c.speed * std::cos(g.theta), 2) + " m/s";
  return f;
}

}  // namespace dualgrid::scenario
