// Rotation invariance (issue 16, docs/algorithm.md "Grid frame"): the same scene turned by 0, 30,
// 45, 90, 135 and 210 degrees -- network built by netconvert from plain XML whose node coordinates
// are rotated, guard rail and parked car rotated with it -- gives the same metrics per mode within
// their 95 % confidence intervals over seeds. With the grid fixed to the world axes
// (filter.frame: world) the 90-degree scene is not covered and the check fails, as it should.
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_harness.hpp"

using namespace dualgrid::testing;

namespace {

constexpr double kPi = 3.14159265358979323846;
// Rounding-level differences between the turned inputs (turns other than multiples of 90 deg
// are inexact) grow into different realisations of the filter, so each angle is a sample of its
// own: the means are compared as samples. |mean_a - mean_b| <= h_a + h_b (the 95 % half-widths
// added) is, for 8 seeds, about 3.3 standard errors of the difference: a family-wise level of
// ~5 % over the ~180 comparisons made here (Bonferroni), so an invariant pipeline passes and a
// real difference (a grid that misses the road) fails.
constexpr int kSeeds = 8;

struct Turned {
  double c, s;
  std::string X(double x, double y) const { return Num(c * x - s * y); }
  std::string Y(double x, double y) const { return Num(s * x + c * y); }
  std::string Point(double x, double y) const {
    std::string p = "[";
    p += X(x, y);
    p += ", ";
    p += Y(x, y);
    return p += "]";
  }
  static std::string Num(double v) {
    std::ostringstream os;
    os.precision(12);
    os << v;
    return os.str();
  }
};

// The road's centre line before turning: straight along x for 1.4 km, or (bend) straight for
// 600 m, a 90-degree left bend of radius 150 m, and 700 m straight north.
std::vector<std::pair<double, double>> RoadLine(bool bend) {
  if (!bend) return {{0, 0}, {1400, 0}};
  std::vector<std::pair<double, double>> line = {{0, 0}};
  // Shape points every 3 deg: a lane's direction then steps by 3 deg, well away from the 5-deg
  // turn threshold (steps of exactly 5 deg would turn the grid, or not, on rounding noise).
  for (int a = 0; a <= 90; a += 3) {
    const double r = a * kPi / 180.0;
    line.emplace_back(600 + 150 * std::sin(r), 150 - 150 * std::cos(r));
  }
  line.emplace_back(750, 850);
  return line;
}

// Writes the scene turned by `deg` into `dir`, builds its network; returns the scenario path.
// `bend`: the road turns left by 90 degrees (RoadLine) after the ego has driven 450 m.
fs::path WriteScene(const fs::path& dir, double deg, bool bend = false, double duration = 10.0) {
  const Turned t{std::cos(deg * kPi / 180.0), std::sin(deg * kPi / 180.0)};
  // A two-lane-each-way road (no junction inside the scene). netconvert would shift a network
  // with negative coordinates to the origin (and the rail and parked car of the YAML with it out
  // of place): --offset.disable-normalization keeps the coordinates.
  const auto line = RoadLine(bend);
  std::string shape, back;
  // "x,y" pairs separated by spaces.
  const auto add = [&t](std::string* to, double x, double y) {
    if (!to->empty()) *to += ' ';
    *to += t.X(x, y);
    *to += ',';
    *to += t.Y(x, y);
  };
  for (const auto& [x, y] : line) add(&shape, x, y);
  for (auto it = line.rbegin(); it != line.rend(); ++it) add(&back, it->first, it->second);
  const auto [ex, ey] = line.back();
  std::ofstream(dir / "road.nod.xml")
      << "<nodes>\n"
      << "  <node id=\"a\" x=\"" << t.X(0, 0) << "\" y=\"" << t.Y(0, 0) << "\"/>\n"
      << "  <node id=\"b\" x=\"" << t.X(ex, ey) << "\" y=\"" << t.Y(ex, ey) << "\"/>\n"
      << "</nodes>\n";
  std::ofstream(dir / "road.edg.xml")
      << "<edges>\n"
      << "  <edge id=\"ab\" from=\"a\" to=\"b\" numLanes=\"2\" speed=\"33.3\" shape=\"" << shape
      << "\"/>\n"
      << "  <edge id=\"ba\" from=\"b\" to=\"a\" numLanes=\"2\" speed=\"33.3\" shape=\"" << back
      << "\"/>\n"
      << "</edges>\n";
  const auto nc =
      Shell(std::string(DUALGRID_NETCONVERT) + " --node-files " + (dir / "road.nod.xml").string() +
            " --edge-files " + (dir / "road.edg.xml").string() +
            " --no-turnarounds true --offset.disable-normalization true -o " +
            (dir / "road.net.xml").string());
  INFO(nc.output);
  REQUIRE(nc.code == 0);
  std::ofstream(dir / "scene.yaml")
      << "name: turned_" << static_cast<int>(deg) << "\n"
      << "network: road.net.xml\nduration: " << duration << "\nstep_length: 0.05\nseed: 1\n"
      << "vehicle_types:\n"
      << "  car: {length: 4.5, width: 1.8, max_speed: 40.0, accel: 2.6, decel: 4.5, rcs_dbsm: 10}\n"
      << "routes:\n  east: [ab]\n  west: [ba]\n"
      << "ego: {id: ego, type: car, route: east, lane: 0, position: 150, speed: 20.0,\n"
      << "      speed_policy: {mode: cruise, speed: 20.0}}\n"
      << "traffic:\n  vehicles:\n"
      << "    - {id: lead, type: car, route: east, lane: 0, position: 185, speed: 19.0,"
         " desired_speed: 19.0, lane_change: false}\n"
      << "    - {id: overtaker, type: car, route: east, lane: 1, position: 120, speed: 26.0,"
         " desired_speed: 26.0, lane_change: false}\n"
      << "    - {id: oncoming, type: car, route: west, lane: 0, position: " << (bend ? 300 : 900)
      << ", speed: 22.0, desired_speed: 22.0, lane_change: false}\n"
      << "obstacles:\n"
      << "  guard_rails:\n"
      << "    - {id: rail, points: [" << t.Point(50, -8.5) << ", " << t.Point(1350, -8.5) << "]}\n"
      << "  parked:\n"
      << "    - {id: parked, center: " << t.Point(420, -11.0)
      << ", yaw: " << Turned::Num(deg * kPi / 180.0)
      << ", length: 4.5, width: 1.8, rcs_dbsm: 10.0}\n";
  return dir / "scene.yaml";
}

using Table = std::map<std::string, std::map<std::string, std::pair<double, double>>>;

// metric key -> mode -> (mean, CI half-width) of an experiment's table.json.
Table RunScene(const fs::path& scenario, const fs::path& out, const std::string& extra = "") {
  const auto r = Run("experiment " + scenario.string() + " --seeds " + std::to_string(kSeeds) +
                     " --no-figures -q --out " + out.string() + extra);
  INFO(r.output);
  REQUIRE(r.code == 0);
  const auto j = nlohmann::json::parse(Slurp(out / "table.json"));
  Table t;
  for (const auto& m : j.at("metrics")) {
    for (const auto& [mode, v] : m.at("values").items()) {
      if (v.at("mean").is_null()) continue;
      const double hw =
          v.at("ci95_half_width").is_null() ? 0.0 : v.at("ci95_half_width").get<double>();
      t[m.at("key").get<std::string>()][mode] = {v.at("mean").get<double>(), hw};
    }
  }
  return t;
}

// Metrics whose means differ beyond both confidence intervals (plus 1e-6 of rounding).
std::vector<std::string> Differences(const Table& base, const Table& other) {
  std::vector<std::string> out;
  for (const auto& [key, modes] : base) {
    for (const auto& [mode, mv] : modes) {
      const auto it = other.find(key);
      if (it == other.end() || !it->second.count(mode)) {
        out.push_back(key + "/" + mode + " missing");
        continue;
      }
      const auto [m0, h0] = mv;
      const auto [m1, h1] = it->second.at(mode);
      if (std::abs(m1 - m0) > h0 + h1 + 1e-6 * (1.0 + std::abs(m0)))
        out.push_back(key + "/" + mode + ": " + std::to_string(m0) + " +- " + std::to_string(h0) +
                      " against " + std::to_string(m1) + " +- " + std::to_string(h1));
    }
  }
  return out;
}

}  // namespace

TEST_CASE("the same scene turned by any angle scores the same, per mode", "[cli][rotation]") {
  const fs::path root = TempDir("rotation", "angles");
  std::map<int, Table> tables;
  for (const int deg : {0, 30, 45, 90, 135, 210}) {
    const fs::path dir = root / std::to_string(deg);
    fs::create_directories(dir);
    tables[deg] = RunScene(WriteScene(dir, deg), dir / "run");
  }
  // The scene is seen at all: the lead is tracked in every mode.
  for (const auto& [mode, v] : tables[0].at("D")) CHECK(v.first > 50.0);
  for (const int deg : {30, 45, 90, 135, 210}) {
    INFO("turned by " << deg << " deg");
    CHECK(Differences(tables[0], tables[deg]) == std::vector<std::string>{});
  }
  // The check can fail: a world-aligned 200 m x 25 m grid lies across the road turned by 90 deg.
  const fs::path world = root / "90_world";
  fs::create_directories(world);
  const Table t = RunScene(WriteScene(world, 90), world / "run", " --set filter.frame=world");
  CHECK_FALSE(Differences(tables[0], t).empty());
}

TEST_CASE("a road that turns: the grid follows it, the same at any angle", "[cli][rotation]") {
  // The road bends left by 90 degrees 450 m ahead of the ego (at 20 m/s: from t = 22 s on). The
  // grid that follows the road (frame: follow, the default) turns with it; the scene turned by
  // other angles scores the same within the confidence intervals. The check can fail: a grid
  // fixed at the start heading (frame: heading) loses the road after the bend.
  const fs::path root = TempDir("rotation", "bend");
  std::map<int, Table> tables;
  for (const int deg : {0, 45, 210}) {
    const fs::path dir = root / std::to_string(deg);
    fs::create_directories(dir);
    tables[deg] = RunScene(WriteScene(dir, deg, true, 40.0), dir / "run");
  }
  for (const auto& [mode, v] : tables[0].at("D")) CHECK(v.first > 50.0);
  for (const int deg : {45, 210}) {
    INFO("turned by " << deg << " deg");
    CHECK(Differences(tables[0], tables[deg]) == std::vector<std::string>{});
  }
  const fs::path fixed = root / "45_heading";
  fs::create_directories(fixed);
  const Table t =
      RunScene(WriteScene(fixed, 45, true, 40.0), fixed / "run", " --set filter.frame=heading");
  CHECK_FALSE(Differences(tables[45], t).empty());
}
