// --set errors name the key as the user typed it and its range in the user's units (issue 42):
// evaluation keys that the validators call otherwise, degrees keys written in degrees, seeds
// bounded like --seed, vClass from SUMO's list.
#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include "dualgrid/scenario/loader.hpp"

using namespace dualgrid;

namespace {

std::string Refusal(const std::string& key_value) {
  const std::string file = std::string(DUALGRID_SOURCE_DIR) + "/scenarios/simple_road.yaml";
  try {
    scenario::LoadScenario(file, {scenario::ParseOverride(key_value)});
  } catch (const scenario::ConfigError& e) {
    return e.what();
  }
  return "accepted";
}

}  // namespace

TEST_CASE("--set errors name the user's key and units", "[scenario][set]") {
  struct Case {
    std::string set, expected;
  };
  const std::vector<Case> cases = {
      {"evaluation.gate_box_margin=-1",
       "key 'evaluation.gate_box_margin' expected finite and >= 0"},
      {"evaluation.gate_center=0", "key 'evaluation.gate_center' expected"},
      {"evaluation.consistent_window=0", "key 'evaluation.consistent_window' expected >= 1, got 0"},
      {"sensors.overrides.front.fov_deg=400",
       "key 'sensors.overrides.front.fov_deg' expected in (0, 360] deg"},
      {"filter.free_angle_bin_deg=400", "key 'filter.free_angle_bin_deg' expected in (0, 57.29"},
      {"seed=9007199254740992", "key 'seed' expected a whole number in [0, 9007199254740991]"},
      {"vehicle_types.car.vclass=spaceship", "key 'vehicle_types.car.vclass' expected a SUMO"},
      {"vehicle_types.car.max_speed=1e300",
       "key 'vehicle_types.car.max_speed' expected in (0, 70]"},
      {"filter.width_y=1e300", "key 'filter.width_y' expected at most 200000000 cells"},
  };
  for (const Case& c : cases) {
    INFO(c.set);
    const std::string message = Refusal(c.set);
    INFO(message);
    CHECK(message.find(c.expected) != std::string::npos);
    CHECK(message.find("association.") == std::string::npos);
    CHECK(message.find(" rad") == std::string::npos);
    CHECK(message.find('\n') == std::string::npos);
  }
  CHECK(Refusal("seed=9007199254740991") == "accepted");
  CHECK(Refusal("sensors.overrides.front.fov_deg=360") == "accepted");
  CHECK(Refusal("vehicle_types.car.vclass=truck") == "accepted");
}
