// `dualgrid tangential --kind aspect` and `--kind guardrail`: the generated geometry is what was
// asked for, measured from the simulation's own ground truth and radar detections
// (docs/stress.md).
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "cli_harness.hpp"

using namespace dualgrid::testing;

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Case {
  std::string sensor;
  double angle, ego_speed, grid_width;
};

}  // namespace

TEST_CASE("aspect cases put the target at the asked aspect angle", "[cli][stress]") {
  // At the reference time (6 s) the target (15 m/s, a car) is 20 m from the sensor on its
  // boresight with its velocity at `angle` to the line of sight. Measured from ground_truth.csv
  // (target centre and velocity at the step nearest 6 s) and the sensor position in
  // detections.csv. Tolerance: SUMO inserts a departing vehicle at the step after its depart time
  // and the depart is rounded to a step, so the target can be up to 2 steps (1.5 m along its
  // path) off its point: the line of sight turns by at most atan(1.5 / 20) = 4.3 deg, the
  // velocity not at all; 5 deg. The mean compensated Doppler of the sensor's detections of the
  // target must be v cos(angle) within 0.5 m/s (noise, rounding) plus the spread of the lines of
  // sight over the car, v |sin(angle)| atan(2.25 / 20) (scatterers all on one side at worst).
  const Case c = GENERATE(Case{"front", 0.0, 0.0, 25.0}, Case{"front", 90.0, 0.0, 25.0},
                          Case{"front", 150.0, 10.0, 25.0}, Case{"front_left", 45.0, 0.0, 60.0},
                          Case{"front_left", 90.0, 0.0, 60.0}, Case{"front_left", 180.0, 0.0, 60.0},
                          Case{"rear_right", 120.0, 8.0, 60.0});
  const fs::path dir = TempDir("stress", c.sensor + "_" + std::to_string(int(c.angle)));
  const auto gen =
      Run("tangential --kind aspect --sensor " + c.sensor + " --angle " + std::to_string(c.angle) +
          " --range 20 --speed 15 --ego-speed " + std::to_string(c.ego_speed) + " --grid-width " +
          std::to_string(c.grid_width) + " --count 1 -q --out " + (dir / "case.yaml").string());
  INFO(gen.output);
  REQUIRE(gen.code == 0);
  const auto sim = Run("sim " + (dir / "case.yaml").string() + " --out " + (dir / "sim").string() +
                       " -q --duration 7");
  INFO(sim.output);
  REQUIRE(sim.code == 0);
  const int step = 120;  // 6.0 s
  double tx = 0, ty = 0, vx = 0, vy = 0;
  bool found = false;
  for (const auto& r : ReadCsv(dir / "sim" / "ground_truth.csv")) {
    if (r.at("id") != "target_1" || std::stoi(r.at("step")) != step) continue;
    tx = std::stod(r.at("x"));
    ty = std::stod(r.at("y"));
    vx = std::stod(r.at("vx"));
    vy = std::stod(r.at("vy"));
    found = true;
  }
  REQUIRE(found);
  double sx = 0, sy = 0, doppler = 0;
  int n = 0;
  for (const auto& r : ReadCsv(dir / "sim" / "detections.csv")) {
    if (r.at("sensor_name") != c.sensor || r.at("source") != "target_1") continue;
    const int s = std::stoi(r.at("step"));
    if (s == step) {
      sx = std::stod(r.at("sensor_x"));
      sy = std::stod(r.at("sensor_y"));
    }
    if (std::abs(s - step) <= 2) {  // +-0.1 s around the reference time
      doppler += std::stod(r.at("radial_speed"));
      ++n;
    }
  }
  REQUIRE(n > 0);
  doppler /= n;
  const double lx = tx - sx, ly = ty - sy;
  const double measured =
      std::acos(
          std::clamp((vx * lx + vy * ly) / (std::hypot(vx, vy) * std::hypot(lx, ly)), -1.0, 1.0)) *
      180.0 / kPi;
  const double speed = std::hypot(vx, vy);
  const double expected_doppler = 15.0 * std::cos(c.angle * kPi / 180.0);
  const double tol = 0.5 + 15.0 * std::abs(std::sin(c.angle * kPi / 180.0)) * std::atan(2.25 / 20);
  INFO(c.sensor << " angle " << c.angle << " ego " << c.ego_speed << ": measured aspect "
                << measured << " deg, range " << std::hypot(lx, ly) << " m, speed " << speed
                << ", mean Doppler " << doppler << " (expected " << expected_doppler << ")");
  CHECK(std::abs(measured - c.angle) < 5.0);
  CHECK(std::abs(std::hypot(lx, ly) - 20.0) < 1.6);
  CHECK(std::abs(speed - 15.0) < 0.1);
  CHECK(std::abs(doppler - expected_doppler) < tol);
}

TEST_CASE("aspect cases that could not be scored are refused with what to change",
          "[cli][stress]") {
  const fs::path dir = TempDir("stress", "refused");
  // 20 m on the front_left boresight lies 15 m to the side: outside an explicit 25 m wide grid.
  const auto narrow =
      Run("tangential --kind aspect --sensor front_left --angle 90 --range 20 "
          "--ego-speed 0 --grid-width 25 -q --out " +
          (dir / "a.yaml").string());
  CHECK(narrow.code == 2);
  CHECK(narrow.output.find("--grid-width 40") != std::string::npos);
  CHECK(CountLines(narrow.output) == 1);
  // Without --grid-width (and without --kind: the aspect options imply it) the grid is widened
  // to the width the error named, and the header says so.
  const auto widened =
      Run("tangential --sensor front_left --angle 90 --range 20 --ego-speed 0 "
          "-q --out " +
          (dir / "w.yaml").string());
  CHECK(widened.code == 0);
  const std::string text = Slurp(dir / "w.yaml");
  CHECK(text.find("filter: {width_y: 40}") != std::string::npos);
  CHECK(text.find("widened from the paper's 25 m to 40 m") != std::string::npos);
  const auto mixed =
      Run("tangential --kind crossing --angle 30 -q --out " + (dir / "m.yaml").string());
  CHECK(mixed.code == 2);
  CHECK(mixed.output.find("options of --kind aspect") != std::string::npos);
  const auto far =
      Run("tangential --kind aspect --sensor front_left --range 150 --ego-speed 0 "
          "--grid-width 400 -q --out " +
          (dir / "b.yaml").string());
  CHECK(far.code == 2);
  CHECK(far.output.find("--range") != std::string::npos);
  // Crossing and parallel traffic need a moving ego.
  const auto parked =
      Run("tangential --kind crossing --ego-speed 0 -q --out " + (dir / "c.yaml").string());
  CHECK(parked.code == 2);
  CHECK(parked.output.find("--ego-speed") != std::string::npos);
}

TEST_CASE("guardrail cases: vehicles pass on the ego's far side, their ghosts lie beyond the rail",
          "[cli][stress][multipath]") {
  // The ego in the highway's left lane (y = -3.75 m), the rail 3 m to its left (y = -0.75 m),
  // three vehicles overtaking at 26 m/s in lanes 1 and 0 (y = -7.25, -10.75 m). With multipath on
  // every ghost is one of theirs off the rail; an order-3 ghost is a mirror image: beyond the
  // rail, where a near face at y < -6 has its image at y > 4.5 (noise: centimetres).
  const fs::path dir = TempDir("stress", "guardrail");
  const auto gen =
      Run("tangential --kind guardrail --offset 3 --ego-speed 20 --speed 26 "
          "--count 3 -q --out " +
          (dir / "case.yaml").string());
  INFO(gen.output);
  REQUIRE(gen.code == 0);
  const auto sim = Run("sim " + (dir / "case.yaml").string() + " --out " + (dir / "sim").string() +
                       " -q --duration 10 --set sensors.multipath=on");
  INFO(sim.output);
  REQUIRE(sim.code == 0);
  double ego_y = 0.0;
  std::map<std::string, double> lane_y, speed_sum, rows;
  for (const auto& r : ReadCsv(dir / "sim" / "ground_truth.csv")) {
    if (r.at("is_ego") == "1") {
      ego_y = std::stod(r.at("y"));
      continue;
    }
    lane_y[r.at("id")] = std::stod(r.at("y"));
    speed_sum[r.at("id")] += std::stod(r.at("speed"));
    rows[r.at("id")] += 1.0;
  }
  CHECK(ego_y == Approx(-3.75).margin(0.05));
  REQUIRE(lane_y.size() == 3);
  for (const auto& [id, y] : lane_y) {
    CHECK(y < ego_y - 3.0);  // the ego's other side
    // They overtake: SUMO's drivers keep near their desired 26 m/s (the ego drives 20 m/s).
    CHECK(speed_sum[id] / rows[id] > 23.0);
  }
  int ghosts = 0, images = 0;
  for (const auto& r : ReadCsv(dir / "sim" / "detections.csv")) {
    if (r.at("path") == "direct" || r.at("path") == "clutter") continue;
    ++ghosts;
    CHECK(r.at("reflector") == "rail");
    CHECK(r.at("ghost_of").rfind("pass_", 0) == 0);
    CHECK(r.at("source") == "clutter");  // a ghost is no object's detection
    if (r.at("bounces") == "3") {
      ++images;
      CHECK(std::stod(r.at("y")) > -0.75);
    }
  }
  CHECK(ghosts > 0);
  CHECK(images > 0);
}

TEST_CASE("guardrail cases that cannot be built are refused with what to change",
          "[cli][stress][multipath]") {
  const fs::path dir = TempDir("stress", "guardrail_bad");
  const auto out = " -q --out " + (dir / "x.yaml").string();
  const auto slow = Run("tangential --kind guardrail --ego-speed 20 --speed 21" + out);
  CHECK(slow.code == 2);
  CHECK_THAT(slow.output, Catch::Contains("--speed must differ from --ego-speed"));
  const auto gap = Run("tangential --kind guardrail --speed 30 --spacing 30" + out);
  CHECK(gap.code == 2);
  CHECK_THAT(gap.output, Catch::Contains("--spacing must be >= 48.0 m"));
  const auto kind = Run("tangential --kind parallel --offset 3" + out);
  CHECK(kind.code == 2);
  CHECK_THAT(kind.output, Catch::Contains("options of --kind guardrail"));
  const auto offset = Run("tangential --kind guardrail --offset 0.5" + out);
  CHECK(offset.code == 2);
  CHECK_THAT(offset.output, Catch::Contains("--offset"));
}
