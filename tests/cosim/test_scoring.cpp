// ModeScorer with and without the classes of ClassifySnapshot: the same scores, bit for bit, and
// the same dynamic cells as the mass threshold itself picks; DynamicParticles' ego box test (only
// cells near the box take it) against testing every particle.
#include <catch2/catch.hpp>

#include <cmath>

#include "../filter/synthetic.hpp"
#include "dualgrid/core/random.hpp"
#include "dualgrid/cosim/scoring.hpp"

using namespace dualgrid;
using namespace dualgrid::filter::testing;

namespace {

void CheckSameClusters(const std::vector<eval::Cluster>& a, const std::vector<eval::Cluster>& b) {
  REQUIRE(a.size() == b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    CHECK(a[k].position == b[k].position);
    CHECK(a[k].velocity == b[k].velocity);
    CHECK(a[k].weight == b[k].weight);
    CHECK(a[k].size == b[k].size);
    CHECK(a[k].min == b[k].min);
    CHECK(a[k].max == b[k].max);
  }
}

// A car crossing in front of a moving ego (radial and tangential motion), seen by two radars,
// so that dynamic cells, clusters and every cell class occur: the grid's cycle of `step`.
struct Crossing {
  static constexpr double kDt = 0.05;
  Pose2 ego;
  Velocity v{2.0, 9.0};
  OrientedBox car;
  static filter::FilterParams Params() {
    filter::FilterParams fp;
    fp.num_particles = 4000;
    fp.num_birth = 400;
    return fp;
  }
  void Step(filter::DynamicGrid& grid, int step) {
    const double t = kDt * step;
    ego.position = {8.0 * t, 0.0};
    car = {Position(25.0, -12.0) + t * v, std::atan2(v.y(), v.x()), 4.5, 1.9};
    const std::vector<filter::SensorCoverage> cov = {ForwardRadar(ego), LeftRadar(ego)};
    std::vector<filter::Measurement> z;
    for (const auto& c : cov)
      for (const Position& p : NearFacePoints(car, c.origin, 1.5, 0.5))
        z.push_back(Detect(p, v, c.origin));
    grid.Update({ego, {8.0, 0.0}}, z, cov, kDt);
  }
};

}  // namespace

TEST_CASE("ModeScorer scores the same with the snapshot's classes, without them or stale ones",
          "[cosim][scoring]") {
  // The crossing car (Crossing).
  filter::DynamicGrid grid(Crossing::Params(), 11);
  const scenario::EvaluationConfig config;
  const double stale_threshold = config.dynamic_threshold + 0.2;
  cosim::ModeScorer with(config), without(config), stale(config);
  // The reference: the particles of cells whose dynamic mass is above the threshold, picked on
  // the float layer itself, clustered as the scorer does.
  eval::ParticleClusterer reference(config.dbscan, config.min_cluster_mass);
  cosim::GridSnapshot s;
  Crossing crossing;
  int dynamic_frames = 0, stale_differs = 0;
  for (int step = 0; step < 40; ++step) {
    const double t = Crossing::kDt * step;
    crossing.Step(grid, step);
    const Pose2& ego = crossing.ego;
    const OrientedBox& car = crossing.car;
    const Velocity& v = crossing.v;

    const std::vector<eval::TruthObject> objects = {{1, car, v, true, true, true}};
    const std::vector<std::uint8_t> truth(static_cast<std::size_t>(grid.cells_x()) * grid.cells_y(),
                                          static_cast<std::uint8_t>(eval::CellClass::kFree));
    const OrientedBox ego_box{ego.position, 0.0, 4.5, 1.9};
    cosim::TakeSnapshot(grid, false, s);
    REQUIRE(s.classes.empty());
    without.AddFrame(t, grid, s, objects, truth, ego_box);
    cosim::ClassifySnapshot(stale_threshold, s);  // another threshold: the scorer must not use it
    const std::vector<std::uint8_t> stale_classes = s.classes;
    stale.AddFrame(t, grid, s, objects, truth, ego_box);
    cosim::ClassifySnapshot(config.dynamic_threshold, s);
    with.AddFrame(t, grid, s, objects, truth, ego_box);
    stale_differs += stale_classes != s.classes;

    std::vector<eval::WeightedParticle> picked;
    const filter::ParticleSet& p = grid.weighted_particles();
    const BoxTest inside_ego(ego_box);
    grid.ForEachWeightedCellWhere(
        std::span<const float>(s.dynamic), [&](float m) { return m > config.dynamic_threshold; },
        [&](std::size_t, std::int64_t first, std::int64_t last) {
          for (std::int64_t i = first; i < last; ++i) {
            const Position pos(p.x[i], p.y[i]);
            if (p.weight[i] > 0.0f && !inside_ego.Contains(pos))
              picked.push_back({pos, Velocity(p.vx[i], p.vy[i]), p.weight[i]});
          }
        });

    INFO("step " << step);
    CheckSameClusters(with.clusters(), reference.Run(picked));
    CheckSameClusters(with.clusters(), without.clusters());
    CheckSameClusters(stale.clusters(), without.clusters());
    dynamic_frames += with.clusters().empty() ? 0 : 1;
  }
  CHECK(dynamic_frames > 10);  // the comparison saw clusters
  CHECK(stale_differs > 0);    // the stale classes would have changed the scores
  const auto a = with.Result(), b = without.Result(), c = stale.Result();
  REQUIRE(a.cells);
  REQUIRE(b.cells);
  REQUIRE(c.cells);
  CHECK(a.cells->confusion == b.cells->confusion);
  CHECK(c.cells->confusion == b.cells->confusion);
  for (const auto* m : {&a, &c}) {
    CHECK(m->matches == b.matches);
    CHECK(m->position_error == b.position_error);
    CHECK(m->velocity_error == b.velocity_error);
    CHECK(m->tracked_fraction == b.tracked_fraction);
    CHECK(m->clusters_per_scan == b.clusters_per_scan);
  }
}

TEST_CASE("DynamicParticles excludes exactly the particles inside the box, wherever it lies",
          "[cosim][scoring]") {
  // The crossing car above; boxes of several sizes and headings laid over its particles (and
  // one far away), so that the cells near the box (those that take the box test) hold particles
  // inside, on the edge and outside it. Reference: every particle of a dynamic cell tested.
  filter::DynamicGrid grid(Crossing::Params(), 11);
  const scenario::EvaluationConfig config;
  Crossing crossing;
  for (int step = 0; step < 30; ++step) crossing.Step(grid, step);
  const OrientedBox& car = crossing.car;
  cosim::GridSnapshot s;
  cosim::TakeSnapshot(grid, false, s);
  cosim::ClassifySnapshot(config.dynamic_threshold, s);
  std::vector<eval::WeightedParticle> all;
  cosim::DynamicParticles(grid, s.classes, std::nullopt, &all);
  REQUIRE(all.size() > 100);
  int boxes_cutting = 0;
  // One vector reused for every box as the scorer reuses its own (longer and shorter results in
  // turn): its old entries must be overwritten and its size set.
  std::vector<eval::WeightedParticle> reused(all.size() + 7);
  for (const double yaw : {0.0, 0.3, 1.2, -2.0}) {
    for (const double size : {0.4, 1.5, 4.0}) {
      for (const Position& shift : {Position(0.0, 0.0), Position(0.7, -0.4), Position(60.0, 9.0)}) {
        const OrientedBox box{car.center + shift, yaw, size, 0.6 * size};
        std::vector<eval::WeightedParticle> kept;
        cosim::DynamicParticles(grid, s.classes, box, &kept);
        std::vector<eval::WeightedParticle> expected;
        for (const eval::WeightedParticle& p : all)
          if (!box.Contains(p.position)) expected.push_back(p);
        cosim::DynamicParticles(grid, s.classes, box, &reused);
        REQUIRE(kept.size() == expected.size());
        REQUIRE(reused.size() == expected.size());
        for (std::size_t i = 0; i < kept.size(); ++i) {
          CHECK(kept[i].position == expected[i].position);
          CHECK(kept[i].velocity == expected[i].velocity);
          CHECK(kept[i].weight == expected[i].weight);
          CHECK(reused[i].position == expected[i].position);
          CHECK(reused[i].weight == expected[i].weight);
        }
        boxes_cutting += kept.size() < all.size() && !kept.empty();
      }
    }
  }
  CHECK(boxes_cutting >= 12);  // most boxes over the car cut its particles in two
}

TEST_CASE("CellWindow holds every cell a box touches", "[cosim][scoring]") {
  filter::FilterParams fp;
  fp.num_particles = 200;
  fp.num_birth = 20;
  filter::DynamicGrid grid(fp, 3);
  grid.Update({Pose2{Position(3.3, -1.7), 0.0}, {0.0, 0.0}}, {}, {}, 0.05);
  CounterRng rng(5, RngPurpose::kTest, 0, 0);
  for (int k = 0; k < 200; ++k) {
    const OrientedBox box{Position(rng.Uniform(-40.0, 40.0), rng.Uniform(-10.0, 10.0)),
                          rng.Uniform(-kPi, kPi), rng.Uniform(0.1, 6.0), rng.Uniform(0.1, 3.0)};
    const cosim::CellWindow w = cosim::CellWindow::Around(box, grid);
    // Points of the box (corners, centre, edge midpoints): each one's cell lies in the window.
    std::vector<Position> pts = {box.center};
    const auto c = box.Corners();
    for (int i = 0; i < 4; ++i) {
      pts.push_back(c[i]);
      pts.push_back(0.5 * (c[i] + c[(i + 1) % 4]));
    }
    for (const Position& p : pts) {
      const auto cell = grid.CellOf(p);
      if (cell) CHECK(w.Holds(cell->x, cell->y));
    }
    // And it is small: the box's bounding rectangle plus a cell each side (3 cells of slack).
    const double r = grid.resolution();
    CHECK(w.x1 - w.x0 <= (std::abs(c[0].x() - c[2].x()) + std::abs(c[1].x() - c[3].x())) / r + 4);
  }
  const OrientedBox nan_box{Position(std::nan(""), 0.0), 0.0, 1.0, 1.0};
  CHECK_FALSE(cosim::CellWindow::Around(nan_box, grid).Holds(0, 0));
}

TEST_CASE("DynamicParticles' cells group its particles by grid cell; clustering in them agrees",
          "[cosim][scoring]") {
  // The crossing car: every particle lies in its run's cell (as the grid's CellOf places it),
  // the runs cover the particles in order, and the clusterer in these cells gives Run's clusters
  // and labels bit for bit, with and without the ego box.
  filter::DynamicGrid grid(Crossing::Params(), 5);
  const scenario::EvaluationConfig config;
  Crossing crossing;
  int compared = 0;
  for (int step = 0; step < 40; ++step) {
    crossing.Step(grid, step);
    if (step < 10) continue;
    cosim::GridSnapshot s;
    cosim::TakeSnapshot(grid, false, s);
    cosim::ClassifySnapshot(config.dynamic_threshold, s);
    for (const std::optional<OrientedBox>& box :
         {std::optional<OrientedBox>(), std::optional<OrientedBox>(crossing.car)}) {
      std::vector<eval::WeightedParticle> particles;
      eval::PointCells cells;
      cosim::DynamicParticles(grid, s.classes, box, &particles, &cells);
      CHECK(cells.side == grid.resolution());
      std::size_t covered = 0;
      for (std::size_t r = 0; r < cells.runs.size(); ++r) {
        const eval::CellRun& run = cells.runs[r];
        CHECK(run.first == static_cast<int>(covered));
        const std::size_t last =
            r + 1 < cells.runs.size() ? cells.runs[r + 1].first : particles.size();
        REQUIRE(last > covered);
        for (std::size_t i = covered; i < last; ++i) {
          const auto cell = grid.CellOf(particles[i].position);
          REQUIRE(cell);
          CHECK(cell->x == run.x);
          CHECK(cell->y == run.y);
          const Position corner = cells.origin + cells.side * Position(run.x, run.y);
          CHECK(particles[i].position.x() >= corner.x() - 1e-4);
          CHECK(particles[i].position.x() <= corner.x() + cells.side + 1e-4);
        }
        covered = last;
      }
      CHECK(covered == particles.size());
      eval::ParticleClusterer in_cells(config.dbscan, config.min_cluster_mass),
          plain(config.dbscan, config.min_cluster_mass);
      CheckSameClusters(in_cells.Run(particles, cells), plain.Run(particles));
      CHECK(std::vector<int>(in_cells.labels().begin(), in_cells.labels().end()) ==
            std::vector<int>(plain.labels().begin(), plain.labels().end()));
      compared += !particles.empty();
    }
  }
  CHECK(compared >= 40);
}
