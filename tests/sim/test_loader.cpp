#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>

#include "dualgrid/scenario/loader.hpp"

using namespace dualgrid;
using scenario::ConfigError;
using scenario::LoadScenario;

namespace {

const char* kValid = R"(
name: tiny
network: highway
duration: 5.0
vehicle_types:
  car: {length: 4.5, width: 1.8}
routes:
  east: [east_1, east_2]
ego: {type: car, route: east, lane: 1, position: 100, speed: 25}
traffic:
  vehicles:
    - {id: a, type: car, route: east, lane: 0, position: 150, speed: 25}
  flows:
    - {id: f, type: car, route: east, begin: 0, end: 5, period: 2}
actions:
  - {time: 2.0, vehicle: a, set_speed: 30}
obstacles:
  guard_rails:
    - {id: r, points: [[0, 0], [100, 0]]}
  parked:
    - {id: p, center: [10, -5], length: 4.5, width: 1.8}
)";

std::filesystem::path Write(const std::string& name, const std::string& text) {
  const auto dir = std::filesystem::temp_directory_path() / "dualgrid_test_loader";
  std::filesystem::create_directories(dir);
  const auto path = dir / name;
  std::ofstream(path) << text;
  return path;
}

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  const auto pos = s.find(from);
  REQUIRE(pos != std::string::npos);
  return s.replace(pos, from.size(), to);
}

// Loads `text` and returns the error message (fails the test if loading succeeds).
std::string ErrorOf(const std::string& text) {
  const auto path = Write("bad.yaml", text);
  try {
    LoadScenario(path);
  } catch (const ConfigError& e) {
    const std::string msg = e.what();
    CHECK(msg.find(path.string()) != std::string::npos);  // names the file
    CHECK(msg.find('\n') == std::string::npos);           // one line
    return msg;
  }
  FAIL("expected a ConfigError for:\n" << text);
  return "";
}

}  // namespace

TEST_CASE("A valid scenario loads with defaults filled in", "[loader]") {
  const auto c = LoadScenario(Write("ok.yaml", kValid));
  CHECK(c.sim.name == "tiny");
  CHECK(c.sim.step_length == Approx(0.05));  // default radar cycle
  CHECK(c.sim.ego.id == "ego");
  CHECK_FALSE(c.sim.ego.lane_change);  // the ego keeps its lane by default
  CHECK(c.sim.routes.at("east").size() == 2);
  CHECK(c.sim.vehicles.size() == 1);
  CHECK(c.sim.flows.size() == 1);
  CHECK(c.sim.actions.at(0).set_speed.value() == Approx(30));
  CHECK(c.sim.guard_rails.at(0).points.size() == 2);
  CHECK(c.sim.parked.at(0).box.center.y() == Approx(-5));
}

TEST_CASE("The shipped scenarios load", "[loader]") {
  const std::string name =
      GENERATE("scenarios/highway.yaml", "scenarios/simple_road.yaml", "scenarios/soak.yaml");
  const auto c = LoadScenario(name);
  CHECK(c.sim.duration > 0);
  CHECK(!(c.sim.vehicles.empty() && c.sim.flows.empty()));
}

TEST_CASE("Malformed scenarios are rejected naming the key and the expectation", "[loader]") {
  struct Case {
    std::string from, to, key, expected;
  };
  const Case c = GENERATE(values<Case>({
      {"duration: 5.0", "duration: five", "'duration'", "expected a number"},
      {"duration: 5.0", "duration: -5", "'duration'",
       "expected in (0, 86400] s (run time), got -5"},
      {"duration: 5.0", "duration: 86400.5", "'duration'", "expected in (0, 86400] s"},
      {"duration: 5.0", "duration: 5.0\nbegin: -1", "'begin'",
       "expected in [0, 31536000] s (SUMO time), got -1"},
      {"duration: 5.0", "duration: 5.0\nbegin: noon", "'begin'", "expected a number"},
      {"duration: 5.0", "duraton: 5.0", "'duraton'", "not a known setting"},
      {"network: highway\n", "", "'network'", "required"},
      {"lane: 1,", "lane: one,", "'ego.lane'", "expected an integer"},
      {"route: east, lane: 0", "route: west, lane: 0", "'traffic.vehicles[0].route'",
       "expected a route of the scenario, got 'west'"},
      {"period: 2}", "period: 2, colour: red}", "'traffic.flows[0].colour'", "not a known setting"},
      {"set_speed: 30", "set_speed: [30]", "'actions[0].set_speed'", "expected a number"},
      {"[[0, 0], [100, 0]]", "[[0, 0], [100]]", "'obstacles.guard_rails[0].points[1]'",
       "expected a point"},
      {"car: {length: 4.5", "car: {length: 0", "'vehicle_types.car.length'",
       "expected in (0, 30] m, got 0"},
      {"vehicle: a", "vehicle: nobody", "'actions[0].vehicle'",
       "expected a vehicle of the scenario, got 'nobody'"},
      {"ego: {", "ego: [", "", "not valid YAML"},
  }));
  const std::string msg = ErrorOf(Replace(kValid, c.from, c.to));
  INFO(msg);
  CHECK(msg.find(c.key) != std::string::npos);
  CHECK(msg.find(c.expected) != std::string::npos);
}

TEST_CASE("A missing scenario file is reported", "[loader]") {
  CHECK_THROWS_WITH(LoadScenario("no/such/file.yaml"), Catch::Contains("not found"));
}

TEST_CASE("Filter and sensor sections are validated by their own structs", "[loader]") {
  const std::string filter_bad = std::string(kValid) + "filter: {sigma_f: -1}\n";
  std::string msg = ErrorOf(filter_bad);
  CHECK(msg.find("'filter.sigma_f'") != std::string::npos);
  const std::string sensor_bad =
      std::string(kValid) + "sensors:\n  overrides:\n    front: {max_range: -5}\n";
  msg = ErrorOf(sensor_bad);
  CHECK(msg.find("sensors.overrides.front") != std::string::npos);
  CHECK(msg.find("max_range") != std::string::npos);
  const std::string mode_bad = std::string(kValid) + "filter: {mode: quantum}\n";
  msg = ErrorOf(mode_bad);
  CHECK(msg.find("'filter.mode' expected 'position', 'velocity' or 'dual'") != std::string::npos);
  const auto ok = LoadScenario(
      Write("ok2.yaml", std::string(kValid) + "filter: {num_particles: 2000, mode: velocity}\n"
                                              "sensors: {noise: false, use: [front]}\n"));
  CHECK(ok.filter.num_particles == 2000);
  CHECK(ok.filter.mode == filter::WeightMode::kVelocity);
  CHECK_FALSE(ok.radar.options.noise);
  REQUIRE(ok.radar.sensors.size() == 1);
  CHECK(ok.radar.sensors[0].name == "front");
}

TEST_CASE("config.json keys read back as scenario keys with the same values", "[loader]") {
  // Change a few values, write the resolved configuration, feed its filter and sensor sections
  // back as YAML (JSON is YAML) and expect the same parameters: one key table serves both ways.
  const auto first = LoadScenario(Write(
      "rt1.yaml", std::string(kValid) +
                      "filter: {num_particles: 3000, sigma_f: 0.45, free_angle_bin_deg: 2.0}\n"
                      "sensors:\n  overrides:\n    front: {max_range: 150, fov_deg: 16}\n"));
  const nlohmann::json j = ConfigToJson(first);
  std::string yaml =
      std::string(kValid) + "filter: " + j.at("filter").dump() + "\nsensors:\n" + "  overrides:\n";
  for (auto s : j.at("sensors").at("rig")) {
    const std::string name = s.at("name");
    s.erase("name");
    yaml += "    " + name + ": " + s.dump() + "\n";
  }
  const auto second = LoadScenario(Write("rt2.yaml", yaml));
  CHECK(second.filter.num_particles == 3000);
  CHECK(second.filter.sigma_f == Approx(0.45));
  CHECK(second.filter.free_angle_bin == Approx(first.filter.free_angle_bin));
  CHECK(ConfigToJson(second).at("filter") == j.at("filter"));
  for (std::size_t i = 0; i < first.radar.sensors.size(); ++i) {
    CHECK(second.radar.sensors[i].max_range == Approx(first.radar.sensors[i].max_range));
    CHECK(second.radar.sensors[i].fov == Approx(first.radar.sensors[i].fov));
    CHECK(second.radar.sensors[i].mount.yaw == Approx(first.radar.sensors[i].mount.yaw));
  }
}

TEST_CASE("filter presets set the switches and single keys override them", "[loader][switches]") {
  using filter::WeightMode;
  const auto paper = LoadScenario(
      Write("preset.yaml", std::string(kValid) + "filter: {preset: paper, sigma_v: 2.0}\n"));
  CHECK(paper.filter_preset == "paper");
  CHECK(paper.filter.birth_velocity == filter::BirthVelocity::kUniform);
  CHECK(paper.filter.zero_likelihood == filter::ZeroLikelihood::kLiteral);
  CHECK(paper.filter.velocity_likelihood == filter::VelocityLikelihood::kVector);
  CHECK(paper.filter.normalisation == filter::Normalisation::kLiteral);
  CHECK(paper.filter.sigma_v == 2.0);
  // A key after the preset wins, wherever it stands in the map.
  const auto mixed = LoadScenario(Write(
      "mixed.yaml", std::string(kValid) + "filter: {normalisation: per_cell, preset: paper}\n"));
  CHECK(mixed.filter.normalisation == filter::Normalisation::kPerCell);
  CHECK(mixed.filter.zero_likelihood == filter::ZeroLikelihood::kLiteral);
  // Per mode births; unlisted modes keep the section's value.
  const auto per_mode = LoadScenario(Write(
      "births.yaml",
      std::string(kValid) + "filter: {birth_velocity: {position: uniform, velocity: doppler}}\n"));
  CHECK(per_mode.FilterFor(WeightMode::kPosition).birth_velocity ==
        filter::BirthVelocity::kUniform);
  CHECK(per_mode.FilterFor(WeightMode::kVelocity).birth_velocity ==
        filter::BirthVelocity::kDoppler);
  // dual is not listed: the section's value, the default doppler_fit.
  CHECK(per_mode.FilterFor(WeightMode::kDual).birth_velocity == filter::BirthVelocity::kDopplerFit);
  CHECK(per_mode.FilterFor(WeightMode::kPosition).mode == WeightMode::kPosition);
  const nlohmann::json j = ConfigToJson(per_mode);
  CHECK(j.at("filter").at("birth_velocity").at("position") == "uniform");
  CHECK(j.at("filter").at("birth_velocity").at("dual") == "doppler_fit");
}

TEST_CASE("--set overrides are applied to the document before it is read", "[loader][set]") {
  const auto path = Write("set.yaml", kValid);
  const auto c = LoadScenario(path, {scenario::ParseOverride("filter.preset=paper"),
                                     scenario::ParseOverride("filter.num_particles=3000"),
                                     scenario::ParseOverride("traffic.vehicles.0.speed=31.5"),
                                     scenario::ParseOverride("duration=4")});
  CHECK(c.filter_preset == "paper");
  CHECK(c.filter.num_particles == 3000);
  REQUIRE(c.sim.vehicles.size() == 1);
  CHECK(c.sim.vehicles[0].speed == 31.5);
  CHECK(c.sim.duration == 4.0);
  // Validated as the file is: the error names the file and the key.
  try {
    LoadScenario(path, {scenario::ParseOverride("filter.sigma_v=-1")});
    FAIL("expected a ConfigError");
  } catch (const ConfigError& e) {
    CHECK(std::string(e.what()).find("sigma_v") != std::string::npos);
    CHECK(std::string(e.what()).find(path.string()) != std::string::npos);
  }
  CHECK_THROWS_AS(scenario::ParseOverride("no_equals"), ConfigError);
  CHECK_THROWS_AS(LoadScenario(path, {scenario::ParseOverride("duration.x=1")}), ConfigError);
  CHECK_THROWS_AS(LoadScenario(path, {scenario::ParseOverride("traffic.vehicles.5.speed=1")}),
                  ConfigError);
}

TEST_CASE("sensors.accuracy and sensors.overrides.all", "[loader][sensors]") {
  const auto clean = LoadScenario(
      Write("clean.yaml", std::string(kValid) +
                              "sensors:\n  accuracy: clean\n  overrides:\n"
                              "    all: {range_rate_accuracy: 0.3}\n"
                              "    front: {range_rate_accuracy: 0.05, off_boresight_deg: [0, 5],\n"
                              "            off_boresight_resolution: [1, 2],\n"
                              "            off_boresight_accuracy: [1, 3]}\n"));
  CHECK(clean.radar.accuracy == "clean");
  for (const auto& s : clean.radar.sensors) {
    INFO(s.name);
    // The named override wins over "all", whatever their order in the file.
    CHECK(s.range_rate_accuracy == (s.name == "front" ? 0.05 : 0.3));
    if (s.name != "front") CHECK(s.off_boresight.empty());  // clean: no profile
    CHECK(s.azimuth_accuracy == Approx(0.1 * s.azimuth_resolution));
  }
  const auto& front = clean.radar.sensors.back();
  REQUIRE(front.name == "front");
  CHECK(front.AzimuthResolutionAt(DegToRad(5.0)) == Approx(2.0 * front.azimuth_resolution));
  const nlohmann::json j = ConfigToJson(clean);
  CHECK(j.at("sensors").at("accuracy") == "clean");
  CHECK(j.at("sensors").at("rig").back().at("off_boresight_deg").at(1) == Approx(5.0));
  // Data sheet by default; bad values name the key.
  CHECK(LoadScenario(Write("ds.yaml", kValid)).radar.accuracy == "datasheet");
  CHECK(ErrorOf(std::string(kValid) + "sensors: {accuracy: perfect}\n").find("sensors.accuracy") !=
        std::string::npos);
  CHECK(ErrorOf(std::string(kValid) + "sensors: {overrides: {all: {off_boresight_deg: [0, 10]}}}\n")
            .find("off_boresight") != std::string::npos);
}

TEST_CASE("grid frame and placement keys", "[loader][frame]") {
  const auto d = LoadScenario(Write("frame0.yaml", kValid));
  CHECK(d.grid.frame == scenario::GridPlacement::Frame::kFollow);  // the default
  CHECK(d.grid.realign_deg == 5.0);
  CHECK(d.grid.CentreOffset(200.0, 25.0) == Vector2::Zero());  // the ego centred, exactly
  const auto w = LoadScenario(
      Write("frame1.yaml", std::string(kValid) + "filter: {frame: world, ahead: 150, left: 10}\n"));
  CHECK(w.grid.frame == scenario::GridPlacement::Frame::kWorld);
  // 150 m ahead of a 200 m grid: its centre 50 m ahead of the ego; 10 m to the left edge of 25.
  CHECK(w.grid.CentreOffset(w.filter.length_x, w.filter.width_y).x() == Approx(50.0));
  CHECK(w.grid.CentreOffset(w.filter.length_x, w.filter.width_y).y() == Approx(-2.5));
  CHECK(ErrorOf(std::string(kValid) + "filter: {frame: diagonal}\n")
            .find("'filter.frame' expected 'follow', 'heading' or 'world', got 'diagonal'") !=
        std::string::npos);
  const auto f =
      LoadScenario(Write("frame4.yaml", std::string(kValid) + "filter: {realign_deg: 2}\n"));
  CHECK(f.grid.realign_deg == 2.0);
  CHECK(ErrorOf(std::string(kValid) + "filter: {realign_deg: 0}\n")
            .find("'filter.realign_deg' expected an angle in (0, 90] deg, got 0") !=
        std::string::npos);
  CHECK(ErrorOf(std::string(kValid) + "filter: {frame: heading, realign_deg: 3}\n")
            .find("'filter.realign_deg' is used only with frame: follow") != std::string::npos);
  CHECK(ErrorOf(std::string(kValid) + "filter: {ahead: 250}\n")
            .find("'filter.ahead' expected a distance in [0, length_x = 200] m, got 250") !=
        std::string::npos);
  // Checked against the extent given in the same section, whatever the key order.
  CHECK_NOTHROW(LoadScenario(
      Write("frame2.yaml", std::string(kValid) + "filter: {ahead: 250, length_x: 300}\n")));
  CHECK_NOTHROW(LoadScenario(
      Write("frame3.yaml", std::string(kValid) + "filter: {length_x: 300, ahead: 250}\n")));
}

TEST_CASE("begin: the run's start on SUMO's clock, and a day-long duration", "[loader][begin]") {
  auto c = LoadScenario(Write("day.yaml", Replace(kValid, "duration: 5.0", "duration: 86400")));
  CHECK(c.sim.duration == 86400.0);  // a day of simulated traffic is accepted
  CHECK(c.sim.begin == 0.0);
  CHECK(c.sim.begin_source == "default");
  c = LoadScenario(
      Write("begin.yaml", Replace(kValid, "duration: 5.0", "duration: 5.0\nbegin: 25200")));
  CHECK(c.sim.begin == 25200.0);
  CHECK(c.sim.begin_source == "scenario");
  // config.json records it beside the duration that counts from it.
  const nlohmann::json j = scenario::ConfigToJson(c);
  CHECK(j.at("begin_s") == 25200.0);
  CHECK(j.at("begin_source") == "scenario");
}

TEST_CASE("the auto rule's view is the grid as the filter places it", "[loader][begin]") {
  auto c = LoadScenario(
      Write("view.yaml",
            std::string(kValid) + "filter: {length_x: 120, width_y: 30, ahead: 90, left: 10}\n"));
  CHECK(c.sim.auto_ego_view.ahead == Approx(90));
  CHECK(c.sim.auto_ego_view.behind == Approx(30));
  CHECK(c.sim.auto_ego_view.left == Approx(10));
  CHECK(c.sim.auto_ego_view.right == Approx(20));
}
