// ModeScorer with and without the classes of ClassifySnapshot: the same scores, bit for bit.
#include <catch2/catch.hpp>

#include "../filter/synthetic.hpp"
#include "dualgrid/cosim/scoring.hpp"

using namespace dualgrid;
using namespace dualgrid::filter::testing;

TEST_CASE("ModeScorer scores the same with the snapshot's classes, without them or stale ones",
          "[cosim][scoring]") {
  // A car crossing in front of a moving ego (radial and tangential motion), seen by two radars,
  // so that dynamic cells, clusters and every cell class occur.
  filter::FilterParams fp;
  fp.num_particles = 4000;
  fp.num_birth = 400;
  filter::DynamicGrid grid(fp, 11);
  const scenario::EvaluationConfig config;
  cosim::ModeScorer with(config), without(config), stale(config);
  cosim::GridSnapshot s;
  Pose2 ego;
  int dynamic_frames = 0;
  for (int step = 0; step < 40; ++step) {
    const double t = 0.05 * step;
    ego.position = {8.0 * t, 0.0};
    const Velocity v(2.0, 9.0);
    const OrientedBox car{Position(25.0, -12.0) + t * v, std::atan2(v.y(), v.x()), 4.5, 1.9};
    const std::vector<filter::SensorCoverage> cov = {ForwardRadar(ego), LeftRadar(ego)};
    std::vector<filter::Measurement> z;
    for (const auto& c : cov)
      for (const Position& p : NearFacePoints(car, c.origin, 1.5, 0.5))
        z.push_back(Detect(p, v, c.origin));
    grid.Update({ego, {8.0, 0.0}}, z, cov, 0.05);

    const std::vector<eval::TruthObject> objects = {{1, car, v, true, true, true}};
    const std::vector<std::uint8_t> truth(static_cast<std::size_t>(grid.cells_x()) * grid.cells_y(),
                                          static_cast<std::uint8_t>(eval::CellClass::kFree));
    const OrientedBox ego_box{ego.position, 0.0, 4.5, 1.9};
    cosim::TakeSnapshot(grid, false, s);
    REQUIRE(s.classes.empty());
    without.AddFrame(t, grid, s, objects, truth, ego_box);
    cosim::ClassifySnapshot(config.dynamic_threshold + 0.2, s);  // another threshold: not used
    stale.AddFrame(t, grid, s, objects, truth, ego_box);
    cosim::ClassifySnapshot(config.dynamic_threshold, s);
    with.AddFrame(t, grid, s, objects, truth, ego_box);

    INFO("step " << step);
    REQUIRE(with.clusters().size() == without.clusters().size());
    REQUIRE(stale.clusters().size() == without.clusters().size());
    for (std::size_t k = 0; k < with.clusters().size(); ++k) {
      CHECK(with.clusters()[k].position == without.clusters()[k].position);
      CHECK(with.clusters()[k].velocity == without.clusters()[k].velocity);
      CHECK(stale.clusters()[k].weight == without.clusters()[k].weight);
    }
    dynamic_frames += with.clusters().empty() ? 0 : 1;
  }
  CHECK(dynamic_frames > 10);  // the comparison saw clusters
  const auto a = with.Result(), b = without.Result(), c = stale.Result();
  REQUIRE(a.cells);
  CHECK(a.cells->confusion == b.cells->confusion);
  CHECK(c.cells->confusion == b.cells->confusion);
  CHECK(a.matches == b.matches);
  CHECK(a.position_error == b.position_error);
  CHECK(a.velocity_error == b.velocity_error);
}
