// WalkEdges (radar_model/src/edge_walk.hpp), the guard rails' walk on SIMD lanes: every edge's
// samples must be WalkEdge's (scan_geometry.hpp, the scalar walk the boxes still use) bit for
// bit, in the same order, whatever the number of edges, their lengths and the sensor's place.
#include <catch2/catch.hpp>

#include <cstring>
#include <vector>

#include "../../radar_model/src/edge_walk.hpp"
#include "../../radar_model/src/scan_geometry.hpp"
#include "dualgrid/core/random.hpp"

using namespace dualgrid;
using namespace dualgrid::radar::detail;

namespace {

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

std::vector<EdgeSample> ScalarWalk(const Edge& e, const Position& s, double range_res,
                                   double azimuth_res) {
  std::vector<EdgeSample> out;
  WalkEdge(e.a, e.b, s, range_res, azimuth_res, [&](const Position& q, double ds, double) {
    out.push_back({q, ds});
  });
  return out;
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

TEST_CASE("WalkEdges gives WalkEdge's samples bit for bit", "[radar][edge_walk]") {
  std::vector<std::vector<EdgeSample>> walks;  // reused across scenes, as the scan's scratch
  std::size_t compared = 0;
  for (std::uint32_t scene = 0; scene < 60; ++scene) {
    CounterRng rng(23, RngPurpose::kTest, scene, 0);
    const Position s(rng.Uniform(-500.0, 500.0), rng.Uniform(-20.0, 20.0));
    const double range_res = rng.Uniform(0.1, 1.0), azimuth_res = rng.Uniform(0.005, 0.1);
    const int n = static_cast<int>(scene % 11);  // 0 to 10: groups of lanes and leftovers
    std::vector<Edge> edges;
    for (int i = 0; i < n; ++i) edges.push_back(RandomEdge(rng, s));
    WalkEdges(edges.data(), n, s, range_res, azimuth_res, &walks);
    REQUIRE(walks.size() >= static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      const std::vector<EdgeSample> expected = ScalarWalk(edges[i], s, range_res, azimuth_res);
      INFO("scene " << scene << ", edge " << i);
      REQUIRE(walks[i].size() == expected.size());
      for (std::size_t k = 0; k < expected.size(); ++k) {
        const bool same = SameBits(walks[i][k].q.x(), expected[k].q.x()) &&
                          SameBits(walks[i][k].q.y(), expected[k].q.y()) &&
                          SameBits(walks[i][k].ds, expected[k].ds);
        if (!same) FAIL_CHECK("sample " << k << " differs");
        ++compared;
      }
    }
  }
  CHECK(compared > 10000);  // the scenes reached long walks, not only empty ones
}

TEST_CASE("WalkEdges on a sensor sitting on the edge and on an empty edge", "[radar][edge_walk]") {
  const Position s(2.0, 1.0);
  const Edge edges[3] = {{Position(2.0, 1.0), Position(4.0, 1.0)},    // starts at the sensor
                         {Position(0.0, 1.0), Position(0.0, 1.0)},    // empty
                         {Position(-1.0, 1.0), Position(5.0, 1.0)}};  // runs through it
  std::vector<std::vector<EdgeSample>> walks(5);
  walks[1].push_back({Position(9.0, 9.0), 1.0});  // stale entries are cleared
  WalkEdges(edges, 3, s, 0.2, 0.02, &walks);
  CHECK(walks[1].empty());
  for (int i : {0, 2}) {
    const std::vector<EdgeSample> expected = ScalarWalk(edges[i], s, 0.2, 0.02);
    REQUIRE(walks[i].size() == expected.size());
    if (i == 0) CHECK(walks[i].front().ds == kMinSpacing);  // the first step, at the sensor
    for (std::size_t k = 0; k < expected.size(); ++k) {
      CHECK(SameBits(walks[i][k].q.x(), expected[k].q.x()));
      CHECK(SameBits(walks[i][k].ds, expected[k].ds));
    }
  }
}
