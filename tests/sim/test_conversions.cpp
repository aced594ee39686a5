#include <catch2/catch.hpp>

#include "dualgrid/sim/conversions.hpp"
#include "dualgrid/sim/scenario.hpp"

using namespace dualgrid;
using namespace dualgrid::sim;

TEST_CASE("SUMO angle to yaw: compass points", "[sim][frames]") {
  CHECK(SumoAngleToYaw(0.0) == Approx(kPi / 2));             // north -> +y
  CHECK(SumoAngleToYaw(90.0) == Approx(0.0).margin(1e-12));  // east -> +x
  CHECK(SumoAngleToYaw(180.0) == Approx(-kPi / 2));          // south -> -y
  CHECK(std::abs(SumoAngleToYaw(270.0)) == Approx(kPi));     // west -> -x
}

TEST_CASE("SUMO angle to yaw: heading vectors agree for all angles", "[sim][frames][property]") {
  const double deg = GENERATE(range(-720.0, 720.0, 7.3));
  const double yaw = SumoAngleToYaw(deg);
  CHECK(yaw > -kPi);
  CHECK(yaw <= kPi);
  // SUMO's heading vector: clockwise from north = (sin a, cos a).
  const double a = DegToRad(deg);
  CHECK(std::cos(yaw) == Approx(std::sin(a)).margin(1e-12));
  CHECK(std::sin(yaw) == Approx(std::cos(a)).margin(1e-12));
  // Round trip.
  const double back = YawToSumoAngle(yaw);
  CHECK(back >= 0.0);
  CHECK(back < 360.0);
  CHECK(std::cos(DegToRad(back - deg)) == Approx(1.0));
}

TEST_CASE("Front bumper to centre lies half a length behind along the heading",
          "[sim][frames][property]") {
  const double yaw = GENERATE(range(-3.1, 3.15, 0.23));
  const double length = GENERATE(3.0, 4.5, 14.0);
  const Position front(123.4, -56.7);
  const Position c = FrontBumperToCenter(front, yaw, length);
  CHECK((front - c).norm() == Approx(0.5 * length));
  // The box with that centre has its front face centre at the bumper.
  const OrientedBox box{c, yaw, length, 1.8};
  const auto corners = box.Corners();
  const Position front_mid = 0.5 * (corners[0] + corners[3]);
  CHECK((front_mid - front).norm() < 1e-9);
  CHECK((CenterToFrontBumper(c, yaw, length) - front).norm() < 1e-9);
}

TEST_CASE("Lane speeds to world velocity", "[sim][frames][property]") {
  const double lane_yaw = GENERATE(range(-3.0, 3.1, 0.5));
  const double speed = GENERATE(0.0, 27.78);
  const double lateral = GENERATE(-1.2, 0.0, 1.2);
  const Velocity v = LaneSpeedsToVelocity(speed, lateral, lane_yaw);
  CHECK(v.dot(UnitVector(lane_yaw)) == Approx(speed).margin(1e-9));
  // Positive lateral speed points to the left of the lane direction.
  CHECK(v.dot(UnitVector(lane_yaw + kPi / 2)) == Approx(lateral).margin(1e-9));
}

TEST_CASE("ScenarioSpec validation names the field", "[sim][config]") {
  ScenarioSpec s;
  s.network = "highway";
  s.vehicle_types["car"] = {};
  s.routes["r"] = {"e1"};
  s.ego.id = "ego";
  s.ego.route = std::string("r");
  std::string error;
  REQUIRE(s.IsValid(&error));

  auto expect = [&](ScenarioSpec bad, const std::string& field) {
    std::string e;
    CHECK_FALSE(bad.IsValid(&e));
    CHECK(e.rfind(field, 0) == 0);
  };
  ScenarioSpec b = s;
  b.step_length = 0.0;
  expect(b, "step_length");
  b = s;
  b.step_length = 0.0505;
  expect(b, "step_length");
  b = s;
  b.ego.route = "nope";
  expect(b, "ego.route");
  b = s;
  b.vehicles.push_back(s.ego);
  expect(b, "traffic.vehicles[0].id");
  b = s;
  b.vehicle_types["car"].length = -1;
  expect(b, "vehicle_types.car.length");
  b = s;
  b.flows.push_back({"f", "car", "r", 10.0, 5.0});
  expect(b, "traffic.flows[0].end");
  b = s;
  ActionSpec ghost;
  ghost.time = 1.0;
  ghost.vehicle = "ghost";
  ghost.set_speed = 20.0;
  b.actions.push_back(ghost);
  expect(b, "actions[0].vehicle");
  b = s;
  b.guard_rails.push_back({"g", {Position(0, 0)}});
  expect(b, "obstacles.guard_rails[0].points");
}
