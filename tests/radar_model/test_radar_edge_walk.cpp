// WalkEdges (radar_model/src/edge_walk.hpp), the guard rails' walk on SIMD lanes: every edge's
// samples must be WalkEdge's (scan_geometry.hpp, the scalar walk the boxes still use) that the
// scan's first tests keep (range and OutsideFov, as RadarModel::VisibleScatterers computes them),
// bit for bit, in the same order, whatever the number of edges, their lengths, the sensor's place
// and heading.
#include <catch2/catch.hpp>

#include <cstring>
#include <vector>

#include "../../radar_model/src/edge_walk.hpp"
#include "../../radar_model/src/scan_geometry.hpp"
#include "dualgrid/core/random.hpp"
#include "dualgrid/radar_model/radar_model.hpp"

using namespace dualgrid;
using namespace dualgrid::radar::detail;

namespace {

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// The scalar path: WalkEdge, then the scan's first tests of each sample.
std::vector<EdgeSample> ScalarWalk(const Edge& e, const SensorCone& c, double range_res,
                                   double azimuth_res, std::size_t* walked = nullptr) {
  std::vector<EdgeSample> out;
  WalkEdge(e.a, e.b, c.position, range_res, azimuth_res, [&](const Position& q, double ds, double) {
    if (walked) ++*walked;
    const Position local = c.to_local * (q - c.position);
    const double range = local.norm();
    if (range < c.min_range || range > c.max_range) return;
    if (OutsideFov(local, range, c.fov_cos_bound)) return;
    out.push_back({q, ds, local, range});
  });
  return out;
}

// WalkEdges' samples gathered per edge (each edge's in the order they came).
std::vector<std::vector<EdgeSample>> Walk(const Edge* edges, int n, const SensorCone& cone,
                                          double range_res, double azimuth_res) {
  std::vector<std::vector<EdgeSample>> walks(n);
  auto sink = [&](int edge, const EdgeSample& sample) {
    REQUIRE(edge >= 0);
    REQUIRE(edge < n);
    walks[edge].push_back(sample);
  };
  WalkEdges(edges, n, cone, range_res, azimuth_res, sink);
  return walks;
}

bool SameSample(const EdgeSample& a, const EdgeSample& b) {
  return SameBits(a.q.x(), b.q.x()) && SameBits(a.q.y(), b.q.y()) && SameBits(a.ds, b.ds) &&
         SameBits(a.local.x(), b.local.x()) && SameBits(a.local.y(), b.local.y()) &&
         SameBits(a.range, b.range);
}

SensorCone RandomCone(CounterRng& rng) {
  SensorCone c;
  c.position = Position(rng.Uniform(-500.0, 500.0), rng.Uniform(-20.0, 20.0));
  c.to_local = Rotation(rng.Uniform(-kPi, kPi)).transpose();
  c.min_range = rng.Uniform(0.0, 1.0);
  c.max_range = rng.Uniform(40.0, 250.0);
  c.fov_cos_bound = FovCosBound(rng.Uniform(0.1, kPi));
  return c;
}

// Random edges as the scan makes them: rail pieces up to a few hundred metres, short box faces,
// empty edges and edges through the sensor (where the scalar walk falls back to kMinSpacing).
Edge RandomEdge(CounterRng& rng, const Position& s) {
  const double kind = rng.Uniform();
  const Position a(s.x() + rng.Uniform(-150.0, 150.0), s.y() + rng.Uniform(-40.0, 40.0));
  if (kind < 0.1) return {a, a};
  if (kind < 0.2) return {s, Position(s.x() + rng.Uniform(-3.0, 3.0), s.y())};
  const double length = kind < 0.5 ? rng.Uniform(0.0, 6.0) : rng.Uniform(50.0, 400.0);
  const double heading = rng.Uniform(-kPi, kPi);
  return {a, a + length * UnitVector(heading)};
}

}  // namespace

TEST_CASE("WalkEdges gives the kept samples of WalkEdge bit for bit", "[radar][edge_walk]") {
  std::size_t walked = 0, kept = 0;
  for (std::uint32_t scene = 0; scene < 60; ++scene) {
    CounterRng rng(23, RngPurpose::kTest, scene, 0);
    const SensorCone cone = RandomCone(rng);
    const double range_res = rng.Uniform(0.1, 1.0), azimuth_res = rng.Uniform(0.005, 0.1);
    const int n = static_cast<int>(scene % 11);  // 0 to 10: groups of lanes and leftovers
    std::vector<Edge> edges;
    for (int i = 0; i < n; ++i) edges.push_back(RandomEdge(rng, cone.position));
    const auto walks = Walk(edges.data(), n, cone, range_res, azimuth_res);
    for (int i = 0; i < n; ++i) {
      const std::vector<EdgeSample> expected =
          ScalarWalk(edges[i], cone, range_res, azimuth_res, &walked);
      INFO("scene " << scene << ", edge " << i);
      REQUIRE(walks[i].size() == expected.size());
      for (std::size_t k = 0; k < expected.size(); ++k)
        if (!SameSample(walks[i][k], expected[k])) FAIL_CHECK("sample " << k << " differs");
      kept += expected.size();
    }
  }
  // The scenes reached long walks, and the cone both kept and dropped many samples.
  CHECK(kept > 5000);
  CHECK(walked - kept > 5000);
}

TEST_CASE("WalkEdges on a sensor sitting on the edge and on an empty edge", "[radar][edge_walk]") {
  SensorCone cone;
  cone.position = Position(2.0, 1.0);
  cone.max_range = 100.0;  // min range 0, all around: every sample kept
  const Edge edges[3] = {{Position(2.0, 1.0), Position(4.0, 1.0)},    // starts at the sensor
                         {Position(0.0, 1.0), Position(0.0, 1.0)},    // empty
                         {Position(-1.0, 1.0), Position(5.0, 1.0)}};  // runs through it
  const auto walks = Walk(edges, 3, cone, 0.2, 0.02);
  CHECK(walks[1].empty());
  for (int i : {0, 2}) {
    const std::vector<EdgeSample> expected = ScalarWalk(edges[i], cone, 0.2, 0.02);
    REQUIRE(walks[i].size() == expected.size());
    REQUIRE(!expected.empty());
    if (i == 0) CHECK(walks[i].front().ds == kMinSpacing);  // the first step, at the sensor
    for (std::size_t k = 0; k < expected.size(); ++k) CHECK(SameSample(walks[i][k], expected[k]));
  }
}

// The scan considers the rail samples as the lanes emit them (several pieces interleaved) and
// then puts the scatterers back piece after piece (GroupByPiece in radar_model.cpp): the order of
// walking the pieces one by one, which the resolution cells' sums depend on. Rails that run
// towards +x with many segments (pieces walked together) must give their scatterers polyline
// after polyline, each along +x.
TEST_CASE("the scan keeps the rails' scatterers in walking order", "[radar][edge_walk]") {
  const radar::RadarModel model(radar::DefaultRig(4.5, 1.8), radar::ModelOptions{}, 1);
  std::size_t rail_scatterers = 0, polylines_seen = 0;
  for (std::uint32_t scene_index = 0; scene_index < 20; ++scene_index) {
    CounterRng rng(29, RngPurpose::kTest, scene_index, 0);
    radar::Scene scene;
    for (int i = 0; i < 4; ++i) {  // occluders
      radar::Target t;
      t.id = i;
      t.box = OrientedBox{Position(rng.Uniform(-60.0, 60.0), rng.Uniform(-8.0, 8.0)),
                          rng.Uniform(-0.3, 0.3), 4.5, 1.8};
      scene.targets.push_back(t);
    }
    for (int i = 0; i < 4; ++i) {
      radar::Polyline line;
      line.id = 1000 + i;
      const double y = (i % 2 == 0 ? -1.0 : 1.0) * rng.Uniform(4.0, 20.0);
      for (double x = -200.0; x < 200.0; x += rng.Uniform(3.0, 60.0))
        line.points.push_back(Position(x, y + rng.Uniform(-0.5, 0.5)));
      scene.polylines.push_back(line);
    }
    radar::EgoMotion ego;
    ego.pose = Pose2{Position(0.0, 0.0), rng.Uniform(-0.2, 0.2)};
    ego.velocity = Velocity(25.0, 0.0);
    ego.length = 4.5;
    ego.width = 1.8;
    for (int sensor = 0; sensor < static_cast<int>(model.sensors().size()); ++sensor) {
      int last_id = -1;
      double last_x = 0.0;
      for (const radar::Scatterer& sc : model.VisibleScatterers(sensor, ego, scene)) {
        if (sc.source_id < 1000) continue;
        ++rail_scatterers;
        INFO("scene " << scene_index << ", sensor " << sensor << ", rail " << sc.source_id);
        REQUIRE(sc.source_id >= last_id);
        if (sc.source_id == last_id) {
          REQUIRE(sc.position.x() > last_x);
        } else {
          ++polylines_seen;
        }
        last_id = sc.source_id;
        last_x = sc.position.x();
      }
    }
  }
  CHECK(rail_scatterers > 10000);
  CHECK(polylines_seen > 100);  // several rails per scan, so pieces of several were interleaved
}
