// GridFrame (core/grid_frame.hpp): a rotation about the world origin, exact identity at yaw 0.
#include <catch2/catch.hpp>

#include "dualgrid/core/grid_frame.hpp"
#include "dualgrid/core/random.hpp"

using dualgrid::CounterRng;
using dualgrid::GridFrame;
using dualgrid::OrientedBox;
using dualgrid::Position;
using dualgrid::RngPurpose;
using dualgrid::Vector2;

TEST_CASE("GridFrame at yaw 0 is the identity bit for bit", "[grid_frame]") {
  const GridFrame g(0.0);
  CHECK(g.identity());
  CounterRng rng(5, RngPurpose::kTest, 0, 0);
  for (int k = 0; k < 100; ++k) {
    const Position p(rng.Uniform(-1e5, 1e5), rng.Uniform(-1e5, 1e5));
    CHECK(g.ToGrid(p) == p);
    CHECK(g.ToWorld(p) == p);
    const double yaw = rng.Uniform(-4.0, 4.0);
    CHECK(g.YawToGrid(yaw) == yaw);
  }
}

TEST_CASE("GridFrame round-trips, preserves distances and turns headings", "[grid_frame]") {
  CounterRng rng(6, RngPurpose::kTest, 0, 0);
  for (int k = 0; k < 200; ++k) {
    const double yaw = rng.Uniform(-7.0, 7.0);
    const GridFrame g(yaw);
    const Position a(rng.Uniform(-5e4, 5e4), rng.Uniform(-5e4, 5e4));
    const Position b(rng.Uniform(-5e4, 5e4), rng.Uniform(-5e4, 5e4));
    CHECK((g.ToWorld(g.ToGrid(a)) - a).norm() <= 1e-9 * (1.0 + a.norm()));
    CHECK((g.ToGrid(a) - g.ToGrid(b)).norm() == Approx((a - b).norm()).epsilon(1e-12).margin(1e-9));
    // The grid's +x axis is the world direction `yaw`.
    const Vector2 x_axis = g.VectorToWorld(Vector2(1.0, 0.0));
    CHECK(x_axis.x() == Approx(std::cos(yaw)).margin(1e-12));
    CHECK(x_axis.y() == Approx(std::sin(yaw)).margin(1e-12));
    // A heading along the grid's x axis is 0 in the grid frame.
    CHECK(std::abs(g.YawToGrid(yaw)) <= 1e-12);
    // Box containment is frame independent.
    const OrientedBox box{a, rng.Uniform(-3.0, 3.0), 4.5, 1.8};
    for (int j = 0; j < 20; ++j) {
      const Position p = a + Vector2(rng.Uniform(-3.0, 3.0), rng.Uniform(-3.0, 3.0));
      const Position local = box.center + dualgrid::Rotation(box.yaw).transpose() * (p - a);
      // Skip points within rounding of the boundary.
      if (std::abs(std::abs(local.x() - a.x()) - 2.25) < 1e-6 ||
          std::abs(std::abs(local.y() - a.y()) - 0.9) < 1e-6)
        continue;
      CHECK(g.ToGrid(box).Contains(g.ToGrid(p)) == box.Contains(p));
    }
  }
}
