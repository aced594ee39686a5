// The stress-case generators of dualgrid::scenario (docs/stress.md) as a library: text out, no
// files, no processes; bad options named.
#include <catch2/catch.hpp>

#include <string>

#include "dualgrid/scenario/aspect_case.hpp"
#include "dualgrid/scenario/guardrail_case.hpp"
#include "dualgrid/scenario/tangential_case.hpp"

using namespace dualgrid::scenario;

TEST_CASE("the aspect case is text naming its network by the stem") {
  AspectCase c;
  c.count = 2;
  const AspectCaseFiles f = MakeAspectCase(c, "my_case");
  CHECK(f.scenario.find("network: my_case.net.xml") != std::string::npos);
  CHECK(f.scenario.find("id: target_2") != std::string::npos);
  CHECK(f.nodes.find("<node id=\"ego_w\"") != std::string::npos);
  CHECK(f.edges.find("<edge id=\"ego_road\"") != std::string::npos);
  // A parked ego puts both targets through one point: one road for both.
  CHECK(f.edges.find("<edge id=\"t1\"") != std::string::npos);
  CHECK(f.edges.find("<edge id=\"t2\"") == std::string::npos);
  // v cos(90 deg) = 0: a purely tangential target.
  CHECK(f.summary == "aspect 90.0 deg to the front radar at 20.0 m, v cos(theta) = 0.00 m/s");
}

TEST_CASE("the aspect case names the option that cannot be built") {
  AspectCase c;
  c.target = "boat";
  CHECK_THROWS_WITH(MakeAspectCase(c, "x"), Catch::StartsWith("--target"));
  c = AspectCase{};
  c.sensor = "roof";
  CHECK_THROWS_WITH(MakeAspectCase(c, "x"), Catch::StartsWith("--sensor"));
  c = AspectCase{};
  c.range = 500.0;
  CHECK_THROWS_WITH(MakeAspectCase(c, "x"), Catch::StartsWith("--range"));
}

TEST_CASE("the aspect case widens the grid only when allowed") {
  AspectCase c;
  c.sensor = "front_left";
  c.angle_deg = 0.0;  // receding along a corner radar's line of sight: out of a 25 m grid soon
  c.range = 30.0;
  CHECK_THROWS_WITH(MakeAspectCase(c, "x"), Catch::Contains("--grid-width"));
  c.auto_grid_width = true;
  const AspectCaseFiles f = MakeAspectCase(c, "x");
  CHECK(f.scenario.find("The grid is widened") != std::string::npos);
  CHECK(f.scenario.find("filter: {width_y:") != std::string::npos);
}

TEST_CASE("the guard-rail case is text, and refuses traffic that never passes") {
  GuardRailCase c;
  const std::string text = GuardRailScenario(c);
  CHECK(text.find("name: guardrail") != std::string::npos);
  CHECK(text.find("id: pass_4") != std::string::npos);
  CHECK(text.find("guard_rails:") != std::string::npos);
  c.speed = c.ego_speed;
  CHECK_THROWS_WITH(GuardRailScenario(c), Catch::StartsWith("--speed"));
  c = GuardRailCase{};
  c.offset = 0.5;
  CHECK_THROWS_WITH(GuardRailScenario(c), Catch::StartsWith("--offset"));
}

TEST_CASE("the crossing and parallel cases are text, with defaults by kind") {
  TangentialCase c;  // crossing
  CHECK(c.Speed() == 15.0);
  CHECK(c.Spacing() == 20.0);
  std::string text = TangentialScenario(c);
  CHECK(text.find("network: crossing") != std::string::npos);
  CHECK(text.find("id: cross_4") != std::string::npos);
  CHECK(text.find("id: cross_5") == std::string::npos);
  CHECK(text.find("focus_object: cross_1") != std::string::npos);
  c.kind = "parallel";
  CHECK(c.Speed() == c.ego_speed + 0.3);
  CHECK(c.Spacing() == 40.0);
  text = TangentialScenario(c);
  CHECK(text.find("network: highway") != std::string::npos);
  CHECK(text.find("id: side_4") != std::string::npos);
  c.kind = "guardrail";  // defaults only: its text is GuardRailScenario's
  CHECK(c.Speed() == c.ego_speed + 5.0);
  CHECK(c.Spacing() == 50.0);
  CHECK_THROWS_WITH(TangentialScenario(c), Catch::StartsWith("--kind"));
}

TEST_CASE("the crossing and parallel cases name the option that cannot be built") {
  TangentialCase c;
  c.ego_speed = 0.0;
  CHECK_THROWS_WITH(TangentialScenario(c), Catch::StartsWith("--ego-speed"));
  c = TangentialCase{};
  c.speed = 20.0;  // 25 m of grid in 1.25 s: too short to be scored
  CHECK_THROWS_WITH(TangentialScenario(c), Catch::StartsWith("--speed 20.0"));
  c = TangentialCase{};
  c.count = 12;
  c.spacing = 60.0;  // 30 + 11 x 60 m beyond the 600 m approach
  CHECK_THROWS_WITH(TangentialScenario(c), Catch::StartsWith("--first-distance"));
  c = TangentialCase{};
  c.kind = "parallel";
  c.speed = c.ego_speed + 6.0;
  CHECK_THROWS_WITH(TangentialScenario(c), Catch::StartsWith("--speed must be within"));
  c.speed.reset();
  c.spacing = 30.0;  // below 18 m + 20 m/s x 1 s
  CHECK_THROWS_WITH(TangentialScenario(c), Catch::StartsWith("--spacing must be >= 38.0"));
}
