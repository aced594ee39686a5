#include "aspect_case.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "dualgrid/core/text.hpp"
#include "dualgrid/core/types.hpp"
#include "dualgrid/outputs/csv_writers.hpp"
#include "dualgrid/outputs/output_file.hpp"
#include "dualgrid/outputs/run_folder.hpp"
#include "dualgrid/radar_model/sensor_params.hpp"

extern char** environ;

namespace dualgrid::tools {
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

// Runs netconvert on the plain-XML files; its output goes to `log`.
void Netconvert(const std::filesystem::path& nod, const std::filesystem::path& edg,
                const std::filesystem::path& net, const std::filesystem::path& log) {
  const std::string exe = DUALGRID_NETCONVERT;
  std::vector<std::string> args = {
      exe,          "--node-files",     nod.string(), "--edge-files",
      edg.string(), "--no-turnarounds", "true",       "--offset.disable-normalization",
      "true",       "--xml-validation", "never",      "--no-warnings",
      "true",       "--output-file",    net.string()};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  // SUMO_HOME for netconvert's data files, unless the user set it.
  std::vector<std::string> env_store;
  for (char** e = environ; *e; ++e) env_store.emplace_back(*e);
  if (!std::getenv("SUMO_HOME"))
    env_store.push_back(std::string("SUMO_HOME=") + DUALGRID_SUMO_HOME);
  std::vector<char*> envp;
  for (auto& e : env_store) envp.push_back(e.data());
  envp.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, exe.c_str(), &fa, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0)
    throw std::runtime_error("cannot start netconvert (" + exe + "): " + std::strerror(rc));
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR)
      throw std::runtime_error("lost netconvert: " + std::string(std::strerror(errno)));
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw std::runtime_error("netconvert failed building " + net.string() + " (see " +
                             log.string() + ")");
}

}  // namespace

std::string WriteAspectCase(const AspectCase& asked, const std::filesystem::path& out) {
  AspectCase c = asked;  // the grid width may be widened below
  const TargetType* type = nullptr;
  for (const auto& t : kTypes)
    if (c.target == t.name) type = &t;
  if (!type) throw std::invalid_argument("--target: expected car, truck or cyclist");
  const auto rig = radar::DefaultRig(kEgoLength, kEgoWidth);
  const radar::SensorParams* sensor = nullptr;
  std::string names;
  for (const auto& s : rig) {
    names += (names.empty() ? "" : ", ") + s.name;
    if (s.name == c.sensor) sensor = &s;
  }
  if (!sensor)
    throw std::invalid_argument("--sensor: expected one of " + names + ", got '" + c.sensor + "'");
  if (c.range <= sensor->min_range + 1.0 || c.range >= sensor->max_range - 5.0)
    throw std::invalid_argument(
        "--range: the " + c.sensor + " radar sees " + FormatFixed(sensor->min_range, 1) + "-" +
        FormatFixed(sensor->max_range, 0) + " m; expected a range within (" +
        FormatFixed(sensor->min_range + 1.0, 1) + ", " + FormatFixed(sensor->max_range - 5.0, 0) +
        ") m, got " + FormatFixed(c.range, 1));
  const double theta = DegToRad(c.angle_deg);
  const double psi = sensor->mount.yaw;  // ego yaw 0: world yaw of the boresight
  const Vector2 los = UnitVector(psi);
  // Velocity direction: the line of sight turned by theta (counter-clockwise).
  const Vector2 dir = UnitVector(psi + theta);
  const double duration = kFirstTime + (c.count - 1) * c.interval + kTailTime;
  const double half_l = 0.5 * type->length;

  // Frames with the centre inside the world-aligned 200 m x `width` grid around the ego (half a
  // cell of margin for the grid's snapping to whole cells).
  const auto frames_in = [&](const Position& p, double t_ref, double depart, double width) {
    int frames = 0;
    for (double time = depart; time <= duration + 1e-9; time += kStep) {
      const Position centre = p + c.speed * (time - t_ref) * dir;
      const double ex = kEgoStartX + c.ego_speed * time;
      frames += std::abs(centre.x() - ex) < 99.5 && std::abs(centre.y()) < 0.5 * width - 0.5;
    }
    return frames;
  };
  const auto FramesInGrid = frames_in;
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
  std::vector<Road> roads;
  std::vector<Target> targets;
  for (int k = 0; k < c.count; ++k) {
    Target t;
    t.t_ref = kFirstTime + k * c.interval;
    const Position sensor_at =
        Position(kEgoStartX + c.ego_speed * t.t_ref, 0.0) + sensor->mount.position;
    t.p = sensor_at + c.range * los;
    t.depart = std::max(0.0, std::round((t.t_ref - kLeadTime) / kStep) * kStep);
    t.pos0 = type->length + 0.1;  // front bumper on the edge at departure
    // Centre at p at t_ref: the edge starts this far before p.
    t.before = t.pos0 + c.speed * (t.t_ref - t.depart) - half_l;
    t.after = c.speed * (duration - t.t_ref) + 50.0;
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
    t.frames_in_grid = FramesInGrid(t.p, t.t_ref, t.depart, c.grid_width);
    targets.push_back(t);
  }
  // Every target must be scored and must be inside the grid at its reference point, where the
  // aspect angle is the asked one. The suggested width is the smallest multiple of 5 m that does.
  const auto fits = [&](double width) {
    for (const auto& t : targets)
      if (frames_in(t.p, t.t_ref, t.depart, width) < kMinFrames ||
          std::abs(t.p.y()) > 0.5 * width - 0.5 - half_l)
        return false;
    return true;
  };
  std::string widened;
  if (!fits(c.grid_width)) {
    double need = 0.0;
    for (double w = 5.0 * std::ceil(c.grid_width / 5.0); w <= 400.0 && need == 0.0; w += 5.0)
      if (fits(w)) need = w;
    if (c.auto_grid_width && need > 0.0) {
      widened = "# The grid is widened from the paper's " + FormatFixed(c.grid_width, 0) +
                " m to " + FormatFixed(need, 0) +
                " m (filter.width_y) so that every target is scored.\n";
      c.grid_width = need;
      for (auto& t : targets) t.frames_in_grid = frames_in(t.p, t.t_ref, t.depart, need);
    }
  }
  if (!fits(c.grid_width)) {
    double need = 0.0;
    for (double w = 5.0 * std::ceil(c.grid_width / 5.0); w <= 400.0 && need == 0.0; w += 5.0)
      if (fits(w)) need = w;
    const Target& t = targets.front();
    std::string why =
        std::abs(t.p.y()) > 0.5 * c.grid_width - 0.5 - half_l
            ? "its reference point, " + FormatFixed(c.range, 1) + " m on the " + c.sensor +
                  " radar's boresight, lies " + FormatFixed(std::abs(t.p.y()), 1) +
                  " m to the side of the ego, outside the " + FormatFixed(c.grid_width, 0) +
                  " m wide grid"
            : "it would be in the " + FormatFixed(c.grid_width, 0) + " m wide grid for " +
                  std::to_string(frames_in(t.p, t.t_ref, t.depart, c.grid_width)) +
                  " frames, fewer than the " + std::to_string(kMinFrames) +
                  " a scored target needs";
    throw std::invalid_argument(
        "the targets would not be scored: " + why + "; " +
        (need > 0.0 ? "use --grid-width " + FormatFixed(need, 0) + ", " : "") +
        "a lower --speed or a shorter --range");
  }

  // Network: the ego's road along world x, and one straight road per target through its
  // reference point; roads cross without junctions (SUMO keeps them independent).
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
    const std::string id = "t" + std::to_string(k + 1);
    nod << "    <node id=\"" << id << "_a\" x=\"" << FormatFixed(a.x(), 3) << "\" y=\""
        << FormatFixed(a.y(), 3) << "\" type=\"priority\"/>\n"
        << "    <node id=\"" << id << "_b\" x=\"" << FormatFixed(b.x(), 3) << "\" y=\""
        << FormatFixed(b.y(), 3) << "\" type=\"priority\"/>\n";
    edg << "    <edge id=\"" << id << "\" from=\"" << id << "_a\" to=\"" << id
        << "_b\" numLanes=\"1\" speed=\"45\" width=\"3.5\" spreadType=\"center\"/>\n";
  }
  nod << "</nodes>\n";
  edg << "</edges>\n";
  const std::filesystem::path base = out.parent_path() / out.stem();
  const auto nod_path = base.string() + ".nod.xml", edg_path = base.string() + ".edg.xml",
             net_path = base.string() + ".net.xml", log_path = base.string() + ".netconvert.log";
  outputs::WriteTextFile(nod_path, nod.str());
  outputs::WriteTextFile(edg_path, edg.str());
  Netconvert(nod_path, edg_path, net_path, log_path);

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
  y << widened << "# Network: " << out.stem().string() << ".net.xml, built by netconvert from "
    << out.stem().string() << ".nod.xml/.edg.xml (roads cross without junctions).\n"
    << "name: aspect_" << c.sensor << "_" << FormatFixed(c.angle_deg, 0) << "\n"
    << "description: targets at aspect angle " << c.angle_deg << " deg to the " << c.sensor
    << " radar's line of sight\n"
    << "network: " << out.stem().string() << ".net.xml\n"
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
  outputs::WriteTextFile(out, y.str());
  return "aspect " + FormatFixed(c.angle_deg, 1) + " deg to the " + c.sensor + " radar at " +
         FormatFixed(c.range, 1) +
         " m, v cos(theta) = " + FormatFixed(c.speed * std::cos(theta), 2) + " m/s";
}

}  // namespace dualgrid::tools
