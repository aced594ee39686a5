// The scenario key sensors.multipath (docs/scenarios.md, docs/radar.md "Multipath"): off by
// default (for every filter preset), on / off as a switch, a map of parameters that turns it on,
// errors naming the key, and config.json recording it only when on.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>

#include "dualgrid/scenario/loader.hpp"

using namespace dualgrid;
using scenario::ConfigError;
using scenario::LoadScenario;

namespace {

const char* kBase = R"(
network: highway
duration: 2.0
routes:
  east: [east_1, east_2]
ego: {type: car, route: east, lane: 1, position: 100, speed: 25}
)";

std::filesystem::path Write(const std::string& text) {
  const auto dir = std::filesystem::temp_directory_path() / "dualgrid_test_loader_multipath";
  std::filesystem::create_directories(dir);
  const auto path = dir / "scenario.yaml";
  std::ofstream(path) << text;
  return path;
}

scenario::ScenarioConfig Load(const std::string& extra,
                              const std::vector<scenario::Override>& overrides = {}) {
  return LoadScenario(Write(std::string(kBase) + extra), overrides);
}

std::string ErrorOf(const std::string& extra) {
  try {
    Load(extra);
  } catch (const ConfigError& e) {
    const std::string msg = e.what();
    CHECK(msg.find('\n') == std::string::npos);
    return msg;
  }
  FAIL("loaded: " << extra);
  return {};
}

}  // namespace

TEST_CASE("sensors.multipath is off unless asked for, whatever the filter preset",
          "[scenario][multipath]") {
  for (const char* preset : {"", "filter: {preset: paper}\n", "filter: {preset: dualgrid}\n"}) {
    const scenario::ScenarioConfig c = Load(preset);
    CHECK_FALSE(c.radar.options.multipath.enabled);
    // config.json does not mention it: runs without multipath keep their files.
    CHECK_FALSE(scenario::ConfigToJson(c).at("sensors").contains("multipath"));
  }
}

TEST_CASE("sensors.multipath: a switch or a map of its parameters", "[scenario][multipath]") {
  for (const char* on : {"on", "true", "yes", "ON"})
    CHECK(Load(std::string("sensors: {multipath: ") + on + "}\n").radar.options.multipath.enabled);
  for (const char* off : {"off", "false", "no"})
    CHECK_FALSE(
        Load(std::string("sensors: {multipath: ") + off + "}\n").radar.options.multipath.enabled);

  const scenario::ScenarioConfig c = Load(
      "sensors:\n  multipath: {rail_loss_db: 9, vehicle_loss_db: 4.5, vehicles: false,\n"
      "              vehicle_min_length: 10, max_bounces: 2, min_pd: 0}\n");
  const radar::MultipathParams& m = c.radar.options.multipath;
  CHECK(m.enabled);  // a map turns it on
  CHECK(m.rails);
  CHECK_FALSE(m.vehicles);
  CHECK(m.rail_loss_db == 9.0);
  CHECK(m.vehicle_loss_db == 4.5);
  CHECK(m.vehicle_min_length == 10.0);
  CHECK(m.max_bounces == 2);
  CHECK(m.min_pd == 0.0);
  const nlohmann::json j = scenario::ConfigToJson(c).at("sensors").at("multipath");
  CHECK(j.at("rail_loss_db") == 9.0);
  CHECK(j.at("max_bounces") == 2);
  CHECK(j.at("vehicles") == false);
  // ... unless it says otherwise.
  CHECK_FALSE(Load("sensors: {multipath: {enabled: false, rail_loss_db: 3}}\n")
                  .radar.options.multipath.enabled);
  // From the command line.
  CHECK(Load("", {{"sensors.multipath", "on"}}).radar.options.multipath.enabled);
  const scenario::ScenarioConfig set = Load("", {{"sensors.multipath.rail_loss_db", "12"}});
  CHECK(set.radar.options.multipath.enabled);
  CHECK(set.radar.options.multipath.rail_loss_db == 12.0);
}

TEST_CASE("sensors.multipath: errors name the key and what was expected", "[scenario][multipath]") {
  CHECK_THAT(ErrorOf("sensors: {multipath: sometimes}\n"),
             Catch::Contains("key 'sensors.multipath' expected on, off or a map") &&
                 Catch::Contains("'sometimes'"));
  CHECK_THAT(ErrorOf("sensors: {multipath: {rail_loss: 3}}\n"),
             Catch::Contains("sensors.multipath.rail_loss"));
  CHECK_THAT(
      ErrorOf("sensors: {multipath: {rail_loss_db: -3}}\n"),
      Catch::Contains("key 'sensors.multipath.rail_loss_db' expected in [0, 60] dB, got -3"));
  CHECK_THAT(ErrorOf("sensors: {multipath: {max_bounces: 4}}\n"),
             Catch::Contains("sensors.multipath.max_bounces") && Catch::Contains("[2, 3]"));
  CHECK_THAT(ErrorOf("sensors: {multipath: {vehicle_min_length: 0}}\n"),
             Catch::Contains("sensors.multipath.vehicle_min_length"));
  CHECK_THAT(ErrorOf("sensors: {multipath: {min_pd: 0.5}}\n"),
             Catch::Contains("sensors.multipath.min_pd"));
  CHECK_THAT(ErrorOf("sensors: {multipath: [on]}\n"), Catch::Contains("sensors.multipath"));
  CHECK_THAT(ErrorOf("sensors: {multipath: {vehicles: maybe}}\n"),
             Catch::Contains("sensors.multipath.vehicles") && Catch::Contains("true or false"));
}
