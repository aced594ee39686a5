#include <catch2/catch.hpp>

#include "dualgrid/core/types.hpp"

using namespace dualgrid;

TEST_CASE("WrapAngle maps into (-pi, pi] and preserves direction", "[core][property]") {
  const double a = GENERATE(range(-20.0, 20.0, 0.37));
  const double w = WrapAngle(a);
  CHECK(w > -kPi);
  CHECK(w <= kPi);
  CHECK(std::cos(w) == Approx(std::cos(a)).margin(1e-12));
  CHECK(std::sin(w) == Approx(std::sin(a)).margin(1e-12));
}

TEST_CASE("Pose2 ToLocal inverts ToParent", "[core][property]") {
  const double yaw = GENERATE(range(-3.1, 3.2, 0.29));
  const double px = GENERATE(-7.5, 0.0, 12.25);
  const Pose2 pose{Position(px, 3.0 - px), yaw};
  const Position local(1.7, -4.2);
  const Position parent = pose.ToParent(local);
  CHECK((pose.ToLocal(parent) - local).norm() < 1e-12);
  CHECK((pose.RotateToLocal(pose.RotateToParent(local)) - local).norm() < 1e-12);
  // The local x axis points along the yaw.
  const Vector2 ex = pose.ToParent(Position(1, 0)) - pose.position;
  CHECK(ex.x() == Approx(std::cos(yaw)).margin(1e-12));
  CHECK(ex.y() == Approx(std::sin(yaw)).margin(1e-12));
}

TEST_CASE("OrientedBox corners lie on its boundary and its centre inside", "[core][property]") {
  const double yaw = GENERATE(range(-3.0, 3.1, 0.5));
  const OrientedBox box{Position(10, -2), yaw, 4.5, 1.8};
  CHECK(box.Contains(box.center));
  for (const Position& c : box.Corners()) {
    CHECK((c - box.center).norm() == Approx(std::hypot(2.25, 0.9)));
    CHECK(box.Contains(box.center + 0.999 * (c - box.center)));
    CHECK_FALSE(box.Contains(box.center + 1.01 * (c - box.center)));
  }
}

TEST_CASE("RigidPointVelocity adds omega cross r", "[core]") {
  const Velocity v = RigidPointVelocity(Velocity(10, 0), 0.5, Position(0, 0), Position(0, 2));
  CHECK(v.x() == Approx(9.0));
  CHECK(v.y() == Approx(0.0).margin(1e-12));
}
