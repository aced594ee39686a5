// DynamicGrid::Reframe: the grid that follows the road turns its frame between cycles
// (docs/algorithm.md, "Grid frame"). Properties over sampled angles: particles turn exactly,
// every cell takes the masses of the old cell under its centre, and a target keeps being tracked
// through the turn.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "dualgrid/filter/dynamic_grid.hpp"
#include "synthetic.hpp"

using namespace dualgrid;
using namespace dualgrid::filter;
using namespace dualgrid::filter::testing;

namespace {

Position Turn(const Position& p, double a) {  // counter-clockwise by a
  return {std::cos(a) * p.x() - std::sin(a) * p.y(), std::sin(a) * p.x() + std::cos(a) * p.y()};
}

// A grid with content: the radial-target case for `cycles` cycles (ego at rest at the origin's
// east, so that a turn about the origin also moves the grid).
DynamicGrid Tracking(int cycles, const Position& ego_at) {
  FilterParams fp;
  fp.num_particles = 4000;
  fp.num_birth = 400;
  DynamicGrid g(fp, 3);
  Pose2 ego;
  ego.position = ego_at;
  const SensorCoverage cov = ForwardRadar(ego);
  for (int k = 0; k < cycles; ++k) {
    const OrientedBox box{ego_at + Vector2(20.0 + 25.0 * 0.05 * k, 0.3), 0.0, 4.5, 1.8};
    std::vector<Measurement> z;
    for (const Position& p : NearFacePoints(box, cov.origin, 1.0, 0.5))
      z.push_back(Detect(p, {25.0, 0.0}, cov.origin));
    // A parked box gives the static layer content too.
    for (double y : {-6.0, -5.5, -5.0})
      z.push_back(Detect(ego_at + Vector2(35.0, y), {0, 0}, cov.origin));
    g.Update({ego, {0, 0}}, z, std::span<const SensorCoverage>(&cov, 1), 0.05);
  }
  return g;
}

}  // namespace

TEST_CASE("Reframe turns every particle exactly and keeps its weights", "[filter][reframe]") {
  const double angle = GENERATE(0.1, -0.7, kPi / 2, 2.5, -kPi);
  const Position ego_at(130.3, -41.7);
  DynamicGrid g = Tracking(15, ego_at);
  const ParticleSet before = g.particles();
  g.Reframe(angle, Turn(ego_at, -angle));
  const ParticleSet& after = g.particles();
  REQUIRE(after.size() == before.size());
  int wrong = 0;
  // The filter keeps positions as float grid-local metres (docs/algorithm.md, "Float state"): the
  // turned position is rounded once to a float of magnitude M = its offset from the new grid's
  // corner [m], |error| <= 2^-24 M, plus the double arithmetic's (~1e-13 m).
  const double r = g.resolution();
  const double x0 = static_cast<double>(g.origin_index()[0]) * r;
  const double y0 = static_cast<double>(g.origin_index()[1]) * r;
  for (std::size_t i = 0; i < before.size(); ++i) {
    const Position p = Turn({before.x[i], before.y[i]}, -angle);
    const Velocity v = Turn(Position(before.vx[i], before.vy[i]), -angle);
    const double tol_x = 0x1p-24 * std::abs(p.x() - x0) + 1e-9;
    const double tol_y = 0x1p-24 * std::abs(p.y() - y0) + 1e-9;
    wrong += std::abs(after.x[i] - p.x()) > tol_x || std::abs(after.y[i] - p.y()) > tol_y ||
             std::abs(after.vx[i] - v.x()) > 1e-5 * (1.0 + v.norm()) ||
             std::abs(after.vy[i] - v.y()) > 1e-5 * (1.0 + v.norm()) ||
             after.weight[i] != before.weight[i] || after.w_position[i] != before.w_position[i] ||
             after.w_velocity[i] != before.w_velocity[i];
  }
  CHECK(wrong == 0);
  // The next cycle (in the new frame) keeps the grid's invariants.
  Pose2 ego;
  ego.position = Turn(ego_at, -angle);
  g.Update({ego, {0, 0}}, {}, {}, 0.05);
  CHECK_FALSE(g.CheckInvariants());
}

TEST_CASE("after Reframe every cell holds the masses of the old cell under its centre",
          "[filter][reframe]") {
  const double angle = GENERATE(0.05, -0.3, kPi / 2, 1.9, -kPi / 2, kPi);
  const Position ego_at(57.9, 12.2);
  DynamicGrid g = Tracking(12, ego_at);
  const DynamicGrid before = g;
  g.Reframe(angle, Turn(ego_at, -angle));
  // The grid is centred on the ego again, in the new frame.
  const Position centre = g.CellCenter({g.cells_x() / 2, g.cells_y() / 2});
  CHECK((centre - Turn(ego_at, -angle)).norm() < 1.5 * g.resolution());
  int checked = 0, content = 0, wrong = 0, outside_not_unknown = 0;
  for (int y = 0; y < g.cells_y(); ++y) {
    for (int x = 0; x < g.cells_x(); ++x) {
      const CellState now = g.Cell({x, y});
      const auto old = before.CellOf(Turn(g.CellCenter({x, y}), angle));
      if (!old) {
        outside_not_unknown += now.unknown != 1.0;
        continue;
      }
      const CellState was = before.Cell(*old);
      wrong +=
          now.free != was.free || now.static_occ != was.static_occ || now.dynamic != was.dynamic;
      ++checked;
      content += was.unknown < 1.0;
    }
  }
  CHECK(wrong == 0);
  CHECK(outside_not_unknown == 0);
  // The turned grids overlap (the ego is in both): at least the square of the short side, 80 %.
  CHECK(checked > 0.8 * g.cells_y() * g.cells_y());
  CHECK(content > 20);  // and the comparison covers cells with content
  // Quarter turns map the lattice onto itself: no cell of the overlap is lost or doubled.
  if (std::abs(std::remainder(angle, kPi / 2)) < 1e-12) {
    std::vector<int> hits(static_cast<std::size_t>(before.cells_x() * before.cells_y()), 0);
    for (int y = 0; y < g.cells_y(); ++y)
      for (int x = 0; x < g.cells_x(); ++x)
        if (const auto old = before.CellOf(Turn(g.CellCenter({x, y}), angle)))
          ++hits[static_cast<std::size_t>(old->y * before.cells_x() + old->x)];
    CHECK(*std::max_element(hits.begin(), hits.end()) == 1);
  }
}

TEST_CASE("a target stays tracked when the frame turns to the road, and is lost without Reframe",
          "[filter][reframe]") {
  // The ego follows a car 8 m ahead, both at 25 m/s, on a straight road heading `angle` in the
  // world (the car's rear is on the long-range radar's line of sight: the Doppler sees its whole
  // speed). For 20 cycles the caller's frame is the world's (the grid lies at `angle` to the
  // road; the car is near enough to stay inside); then the frame turns to the road and every
  // input comes in the turned frame. With Reframe the car's cells stay dynamic and its velocity
  // within 1 m/s (test_targets' bound) through the turn; without, the particles are left where
  // the old frame put them, far from the car.
  const double angle = GENERATE(0.3, kPi / 2, -2.2);
  const bool reframe = GENERATE(true, false);
  FilterParams fp;
  DynamicGrid g(fp, 7);
  const Vector2 road(std::cos(angle), std::sin(angle));
  const Position start(300.0, 80.0);
  double frame = 0.0;
  std::vector<TargetView> views;
  for (int k = 0; k < 60; ++k) {
    if (k == 20) {
      frame = angle;
      if (reframe) g.Reframe(angle, Turn(start + 25.0 * 0.05 * k * road, -frame));
    }
    const Position ego_world = start + 25.0 * 0.05 * k * road;
    const Vector2 side(-road.y(), road.x());
    const Position car_world = ego_world + 8.0 * road + 0.3 * side;
    // The scene turned into the current frame.
    const Pose2 ego{Turn(ego_world, -frame), angle - frame};
    const Velocity v = Turn(Position(25.0 * road), -frame);
    const SensorCoverage cov = ForwardRadar(ego);
    const OrientedBox box{Turn(car_world, -frame), angle - frame, 4.5, 1.8};
    std::vector<Measurement> z;
    for (const Position& p : NearFacePoints(box, cov.origin, 1.0, 0.5))
      z.push_back(Detect(p, v, cov.origin));
    g.Update({ego, v}, z, std::span<const SensorCoverage>(&cov, 1), 0.05);
    REQUIRE_FALSE(g.CheckInvariants());
    TargetView view = LookAt(g, box, 0.5);
    view.mean_velocity -= v;
    views.push_back(view);
  }
  INFO("angle " << angle << " reframe " << reframe);
  for (int k = 10; k < 20; ++k) REQUIRE(views[k].max_dynamic > 0.6);  // tracked before the turn
  if (reframe) {
    double error = 0.0;
    for (int k = 20; k < 60; ++k) {
      INFO("cycle " << k);
      REQUIRE(views[k].max_dynamic > 0.6);
      REQUIRE(views[k].has_particles);
      error += views[k].mean_velocity.norm() / 40.0;
    }
    CHECK(error < 1.0);
  } else {
    // The cycle after the turn: no persistent particle where the car is.
    CHECK(views[20].max_dynamic < 0.6);
  }
}
