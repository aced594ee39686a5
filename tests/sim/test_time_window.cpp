// The run's window on SUMO's clock and the `auto` rule's view, without running SUMO.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "dualgrid/sim/auto_ego.hpp"
#include "dualgrid/sim/scenario.hpp"
#include "dualgrid/sim/sumo_files.hpp"

using namespace dualgrid;
using namespace dualgrid::sim;

namespace {

std::string RouteFile(const std::string& body) {
  const auto path = std::filesystem::temp_directory_path() / "dualgrid_test_window.rou.xml";
  std::ofstream(path) << "<routes>\n" << body << "\n</routes>\n";
  return path.string();
}

}  // namespace

TEST_CASE("a flow member departs as SUMO departs it when the run begins late", "[sim][begin]") {
  const auto index = IndexRouteFiles({RouteFile(
      R"(<flow id="f" begin="0" end="200" period="20" route="r"/>
         <vehicle id="v" depart="25205" route="r"/>
         <vehicle id="t" depart="triggered" route="r"/>)")});
  const auto v = DepartureOf(index, "v");
  REQUIRE(v);
  CHECK(v->At(0.0) == 25205.0);
  CHECK(v->At(30000.0) == 25205.0);  // a vehicle's departure does not move with the begin
  const auto f3 = DepartureOf(index, "f.3");
  REQUIRE(f3);
  CHECK(f3->At(0.0) == 60.0);
  // SUMO starts a flow that began before the run at the run's begin, numbering from 0
  // (measured with SUMO 1.15: begin 100 gives f.0 at 100, f.1 at 120, f.2 at 140).
  CHECK(f3->At(100.0) == 160.0);
  CHECK_FALSE(DepartureOf(index, "f.9")->At(100.0));  // 280 s: past the flow's end
  CHECK_FALSE(DepartureOf(index, "t"));               // "triggered": the files do not say when
}

TEST_CASE("an explicit ego must depart within [begin, begin + duration)", "[sim][begin]") {
  ScenarioSpec s;
  s.network = std::string(5, 'x');  // any name: the network is not read here
  s.route_files = {"x.rou.xml"};
  s.ego_from_routes = true;
  s.ego.id = std::string(1, 'v');
  s.ego_departure = FileDeparture{};
  s.ego_departure->depart = 25205.0;
  std::string error;
  CHECK_FALSE(s.IsValid(&error));
  CHECK(error.find("departs at SUMO time 25205 s") != std::string::npos);
  s.begin = 25200.0;
  CHECK(s.IsValid(&error));
  s.begin = 25210.0;
  CHECK_FALSE(s.IsValid(&error));
  CHECK(error.find("SUMO skips vehicles that depart before the begin") != std::string::npos);
  s.begin = 25200.0;
  s.config_end = 25100.0;  // a begin after the configuration's end
  CHECK_FALSE(s.IsValid(&error));
  CHECK(error.find("the configuration's end = 25100 s") != std::string::npos);
}

TEST_CASE("an empty flow is described as creating no vehicle", "[sim]") {
  const auto index =
      IndexRouteFiles({RouteFile(R"(<flow id="1" begin="0" number="0" route="r"/>)")});
  const auto problem = VehicleIdProblem(index, "1.0");
  REQUIRE(problem);
  CHECK(*problem == "is no member of flow '1', which creates no vehicle");
}

TEST_CASE("the auto rule's view box lies along the vehicle's heading", "[sim][auto]") {
  const ViewBox box{100.0, 20.0, 10.0, 5.0};  // ahead, behind, left, right [m]
  CHECK(box.Contains({90.0, 0.0}, 0.0));
  CHECK_FALSE(box.Contains({110.0, 0.0}, 0.0));
  CHECK(box.Contains({-20.0, 9.9}, 0.0));
  CHECK_FALSE(box.Contains({0.0, -6.0}, 0.0));
  // Heading north: ahead is +y, left is -x.
  const double north = 0.5 * std::acos(-1.0);
  CHECK(box.Contains({0.0, 90.0}, north));
  CHECK(box.Contains({-9.0, 0.0}, north));
  CHECK_FALSE(box.Contains({-11.0, 0.0}, north));
  CHECK_FALSE(box.Contains({90.0, 0.0}, north));
}
