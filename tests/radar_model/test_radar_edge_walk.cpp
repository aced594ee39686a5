// WalkEdges (radar_model/src/edge_walk.hpp), the guard rails' walk on SIMD lanes: every edge's
// samples must be WalkEdge's (scan_geometry.hpp, the scalar walk the boxes still use) that the
// scan's first tests keep (range and OutsideFov, as RadarModel::VisibleScatterers computes them),
// bit for bit, in the same order, whatever the number of edges, their lengths, the sensor's place
// and heading.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstring>
#include <limits>
#include <vector>

#include "../../radar_model/src/edge_walk.hpp"
#include "../../radar_model/src/scan_geometry.hpp"
#include "../../radar_model/src/sensor_scan.hpp"
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

// `count` straight-ish rails alternating left and right of the x axis (4 - 20 m off it), from
// -half_length to half_length [m], with corners every min_gap - max_gap [m].
void AddRandomRails(radar::Scene& scene, CounterRng& rng, int count, double half_length,
                    double min_gap, double max_gap) {
  for (int i = 0; i < count; ++i) {
    radar::Polyline line;
    line.id = 1000 + i;
    const double y = (i % 2 == 0 ? -1.0 : 1.0) * rng.Uniform(4.0, 20.0);
    for (double x = -half_length; x < half_length; x += rng.Uniform(min_gap, max_gap))
      line.points.push_back(Position(x, y + rng.Uniform(-0.5, 0.5)));
    scene.polylines.push_back(line);
  }
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
    AddRandomRails(scene, rng, 4, 200.0, 3.0, 60.0);
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

// The step's scan walks the rail pieces of all its sensors together (one cone per sensor on the
// lanes): each edge must still get the samples of its own cone's scalar walk, bit for bit and in
// order, however many cones and edges share the lanes (fails if a lane reads another lane's
// sensor, resolutions or range limits).
TEST_CASE("WalkEdges with several cones walks each edge for its own cone", "[radar][edge_walk]") {
  std::size_t kept = 0;
  int mixed_groups = 0;
  for (std::uint32_t scene = 0; scene < 40; ++scene) {
    CounterRng rng(31, RngPurpose::kTest, scene, 0);
    const int n_cones = 1 + static_cast<int>(scene % 6);
    std::vector<SensorCone> cones;
    for (int c = 0; c < n_cones; ++c) {
      SensorCone cone = RandomCone(rng);
      if (c > 0) cone.position = cones[0].position + Position(rng.Uniform(-3, 3), 0.0);
      cone.range_res = rng.Uniform(0.1, 1.0);
      cone.azimuth_res = rng.Uniform(0.005, 0.1);
      cones.push_back(cone);
    }
    const int n = static_cast<int>(scene % 17);  // 0 to 16: up to two groups of eight lanes
    std::vector<Edge> edges;
    for (int i = 0; i < n; ++i) {
      const int c = static_cast<int>(rng.Uniform() * n_cones) % n_cones;
      Edge e = RandomEdge(rng, cones[c].position);
      e.cone = c;
      edges.push_back(e);
    }
    std::vector<std::vector<EdgeSample>> walks(n);
    auto sink = [&](int edge, const EdgeSample& sample) {
      REQUIRE(edge >= 0);
      REQUIRE(edge < n);
      walks[edge].push_back(sample);
    };
    WalkEdges(edges.data(), n, cones.data(), sink);
    for (int i = 0; i < n; ++i) {
      const SensorCone& c = cones[edges[i].cone];
      const std::vector<EdgeSample> expected = ScalarWalk(edges[i], c, c.range_res, c.azimuth_res);
      INFO("scene " << scene << ", edge " << i << ", cone " << edges[i].cone);
      REQUIRE(walks[i].size() == expected.size());
      for (std::size_t k = 0; k < expected.size(); ++k)
        if (!SameSample(walks[i][k], expected[k])) FAIL_CHECK("sample " << k << " differs");
      kept += expected.size();
    }
    mixed_groups += n_cones > 1 && n > 1;
  }
  CHECK(kept > 5000);
  CHECK(mixed_groups > 20);
}

namespace {

bool SameDetection(const radar::Detection& a, const radar::Detection& b) {
  return a.sensor == b.sensor && SameBits(a.range, b.range) && SameBits(a.azimuth, b.azimuth) &&
         SameBits(a.range_rate, b.range_rate) && SameBits(a.snr_db, b.snr_db) &&
         SameBits(a.position_world.x(), b.position_world.x()) &&
         SameBits(a.position_world.y(), b.position_world.y()) &&
         SameBits(a.position_ego.x(), b.position_ego.x()) &&
         SameBits(a.position_ego.y(), b.position_ego.y()) &&
         SameBits(a.radial_speed_compensated, b.radial_speed_compensated) &&
         a.source_id == b.source_id && a.is_clutter == b.is_clutter && a.path == b.path &&
         a.bounces == b.bounces && a.reflector_id == b.reflector_id && a.ghost_of == b.ghost_of;
}

}  // namespace

// RadarModel::Scan walks the rails of every due sensor together (ScanRails over all their scans)
// and shares the targets' geometry between them; ScanSensor scans one sensor alone. Both must
// give the same detections bit for bit, with and without multipath, on random scenes of moving
// boxes and multi-segment rails around a turned, moving ego (fails if a rail sample reaches the
// wrong sensor's scan or a sensor's scatterers are not put back piece after piece).
TEST_CASE("Scan with the sensors' rails walked together equals ScanSensor per sensor",
          "[radar][edge_walk]") {
  std::size_t detections = 0, rail_detections = 0;
  for (std::uint32_t scene_index = 0; scene_index < 24; ++scene_index) {
    CounterRng rng(37, RngPurpose::kTest, scene_index, 0);
    radar::ModelOptions options;
    options.multipath.enabled = scene_index % 2 == 1;
    const radar::RadarModel model(radar::DefaultRig(4.5, 1.8), options, scene_index);
    radar::Scene scene;
    for (int i = 0; i < 12; ++i) {
      radar::Target t;
      t.id = i;
      t.box = OrientedBox{Position(rng.Uniform(-70.0, 70.0), rng.Uniform(-10.0, 10.0)),
                          rng.Uniform(-0.4, 0.4), i % 4 == 0 ? 12.0 : 4.5, 1.8};
      t.velocity = Velocity(rng.Uniform(-30.0, 30.0), rng.Uniform(-1.0, 1.0));
      t.yaw_rate = rng.Uniform(-0.2, 0.2);
      scene.targets.push_back(t);
    }
    AddRandomRails(scene, rng, 3, 250.0, 5.0, 200.0);
    radar::EgoMotion ego;
    ego.pose = Pose2{Position(rng.Uniform(-5.0, 5.0), 0.0), rng.Uniform(-0.3, 0.3)};
    ego.velocity = Velocity(rng.Uniform(0.0, 35.0), 0.0);
    ego.yaw_rate = rng.Uniform(-0.1, 0.1);
    ego.length = 4.5;
    ego.width = 1.8;
    const std::uint64_t step = scene_index;
    const std::vector<radar::Detection> together = model.Scan(ego, scene, step, 0.0, 0.05);
    std::vector<radar::Detection> alone;
    for (int sensor = 0; sensor < static_cast<int>(model.sensors().size()); ++sensor)
      for (const radar::Detection& d : model.ScanSensor(sensor, ego, scene, step))
        alone.push_back(d);
    INFO("scene " << scene_index);
    REQUIRE(together.size() == alone.size());
    for (std::size_t k = 0; k < alone.size(); ++k) {
      if (!SameDetection(together[k], alone[k])) FAIL_CHECK("detection " << k << " differs");
      rail_detections += alone[k].source_id >= 1000;
    }
    detections += alone.size();
  }
  CHECK(detections > 2000);
  CHECK(rail_detections > 500);
}

namespace {

bool SameScatterer(const radar::Scatterer& a, const radar::Scatterer& b) {
  return SameBits(a.position.x(), b.position.x()) && SameBits(a.position.y(), b.position.y()) &&
         SameBits(a.rcs_m2, b.rcs_m2) && SameBits(a.truth.range, b.truth.range) &&
         SameBits(a.truth.azimuth, b.truth.azimuth) &&
         SameBits(a.truth.range_rate, b.truth.range_rate) && a.source_id == b.source_id;
}

// A motorway as the scenarios draw it: a median barrier, a rail beyond it (hidden by it) and a
// rail on the near side, each a few long segments, with cars around a turned ego.
radar::Scene MotorwayScene(CounterRng& rng) {
  radar::Scene scene;
  const double ys[3] = {rng.Uniform(2.0, 6.0), rng.Uniform(15.0, 22.0), -rng.Uniform(8.0, 16.0)};
  for (int i = 0; i < 3; ++i) {
    radar::Polyline line;
    line.id = 1000 + i;
    for (double x = -400.0; x < 400.0; x += rng.Uniform(40.0, 500.0))
      line.points.push_back(Position(x, ys[i] + rng.Uniform(-0.3, 0.3)));
    line.points.push_back(Position(400.0, ys[i]));
    if (i == 1 && rng.Uniform() < 0.5) std::reverse(line.points.begin(), line.points.end());
    scene.polylines.push_back(line);
  }
  for (int i = 0; i < 6; ++i) {
    radar::Target t;
    t.id = i;
    t.box = OrientedBox{Position(rng.Uniform(-60.0, 60.0), rng.Uniform(-7.0, 1.0)),
                        rng.Uniform(-0.1, 0.1), 4.5, 1.8};
    t.velocity = Velocity(rng.Uniform(20.0, 35.0), 0.0);
    scene.targets.push_back(t);
  }
  return scene;
}

}  // namespace

// The rail walks are cut (SensorScan::CutRailWalks): a piece stops where the field of view
// ends along it, and a piece that another rail hides whole (the far rail behind the median) is
// not walked. The cuts rest on proofs with margins; the scatterers must be those of the whole
// walks bit for bit and in order, for every sensor of the rig, on scenes where both cuts occur
// (fails if a cut drops a sample the scan keeps).
TEST_CASE("the cut rail walks give the scatterers of the whole walks", "[radar][edge_walk]") {
  const radar::RadarModel model(radar::DefaultRig(4.5, 1.8), radar::ModelOptions{}, 1);
  const radar::ModelOptions& options = model.options();
  std::size_t scatterers = 0, hidden = 0, stopped = 0, pieces = 0;
  for (std::uint32_t scene_index = 0; scene_index < 60; ++scene_index) {
    CounterRng rng(41, RngPurpose::kTest, scene_index, 0);
    const radar::Scene scene = MotorwayScene(rng);
    radar::EgoMotion ego;
    ego.pose = Pose2{Position(rng.Uniform(-20.0, 20.0), rng.Uniform(-6.0, 0.0)),
                     rng.Uniform(-0.4, 0.4) + (scene_index % 4 == 3 ? kPi : 0.0)};
    ego.velocity = Velocity(rng.Uniform(0.0, 35.0), 0.0);
    ego.length = 4.5;
    ego.width = 1.8;
    std::vector<TargetGeometry> targets;
    ComputeTargetGeometry(scene, &targets);
    for (int sensor = 0; sensor < static_cast<int>(model.sensors().size()); ++sensor) {
      ScanScratch cut_scratch, whole_scratch;
      RailWalkScratch walk_scratch;
      SensorScan cut(model.sensors()[sensor], model.sensor_models()[sensor], options, ego, scene,
                     targets, cut_scratch);
      SensorScan whole(model.sensors()[sensor], model.sensor_models()[sensor], options, ego, scene,
                       targets, whole_scratch);
      SensorScan* const cut_scans[1] = {&cut};
      SensorScan* const whole_scans[1] = {&whole};
      ScanRails(cut_scans, walk_scratch, true);
      ScanRails(whole_scans, walk_scratch, false);
      for (const RailPiece& piece : cut.rail_pieces()) {
        ++pieces;
        hidden += piece.walk_end == 0.0;
        stopped += piece.walk_end > 0.0 && piece.walk_end < (piece.b - piece.a).norm();
      }
      INFO("scene " << scene_index << ", sensor " << sensor);
      REQUIRE(cut_scratch.scatterers.size() == whole_scratch.scatterers.size());
      for (std::size_t k = 0; k < whole_scratch.scatterers.size(); ++k)
        if (!SameScatterer(cut_scratch.scatterers[k], whole_scratch.scatterers[k]))
          FAIL_CHECK("scatterer " << k << " differs");
      scatterers += whole_scratch.scatterers.size();
    }
  }
  INFO(pieces << " pieces: " << hidden << " hidden, " << stopped << " stopped early");
  CHECK(scatterers > 20000);
  CHECK(hidden > pieces / 10);
  CHECK(stopped > pieces / 5);
}

// The regions the cuts rest on (MakeRejectedRegions): every point kCutDistance inside a body
// region must be hidden by the ego's body as BehindBody tests it (its line of sight more than
// kEgoBodyMargin inside the shrunk box), every point kCutDistance outside a field-of-view
// half-plane rejected by OutsideFov; and the regions must cover most of what they stand for
// (the body's: all lines of sight into the body but those within a few degrees of the sensor's
// face, so > 80 % of the hidden points 5-100 m away; fails if a region is turned or empty).
TEST_CASE("the rejected regions lie behind the body and outside the field of view",
          "[radar][edge_walk]") {
  std::size_t in_body = 0, hidden = 0, hidden_covered = 0, outside = 0, in_fov_region = 0;
  for (std::uint32_t scene = 0; scene < 200; ++scene) {
    CounterRng rng(43, RngPurpose::kTest, scene, 0);
    const double length = rng.Uniform(3.5, 6.0), width = rng.Uniform(1.6, 2.6);
    const Pose2 ego{Position(rng.Uniform(-500.0, 500.0), rng.Uniform(-50.0, 50.0)),
                    rng.Uniform(-kPi, kPi)};
    Occluder body;
    body.a = ego.position;
    body.axis = UnitVector(ego.yaw);
    body.half_length = 0.5 * length - kEgoBodySkin;
    body.half_width = 0.5 * width - kEgoBodySkin;
    // A sensor on a face, at a corner, or a little off the box.
    Pose2 mount;
    const int kind = static_cast<int>(scene % 4);
    const double side = rng.Uniform() < 0.5 ? -1.0 : 1.0;
    if (kind == 0) mount = {Position(rng.Uniform(-0.5, 0.5) * length, side * 0.5 * width), 0.0};
    if (kind == 1) mount = {Position(side * 0.5 * length, rng.Uniform(-0.5, 0.5) * width), 0.0};
    if (kind == 2) mount = {Position(0.5 * length, side * 0.5 * width), 0.0};
    if (kind == 3)
      mount = {Position(0.5 * length + 0.2, side * rng.Uniform(0.0, 0.6) * width), 0.0};
    mount.yaw = rng.Uniform(-kPi, kPi);
    const Pose2 pose = ego.Compose(mount);
    const Matrix2 to_local = Rotation(pose.yaw).transpose();
    const double half_fov = rng.Uniform(0.05, 1.5);
    const RejectedRegions regions = MakeRejectedRegions(pose.position, to_local, half_fov, &body);
    const auto inside = [](const HalfPlane& h, const Position& q) {
      return h.n.dot(q) - h.offset >= kCutDistance;
    };
    for (int i = 0; i < 400; ++i) {
      const Position q =
          pose.position + rng.Uniform(0.0, 100.0) * UnitVector(rng.Uniform(-kPi, kPi));
      const double chord = LengthInsideBox(body, pose.position, q);
      bool covered = false;
      for (int r = 0; r < regions.body; ++r) {
        const auto& region = regions.behind_body[r];
        if (std::all_of(region.begin(), region.end(),
                        [&](const HalfPlane& h) { return inside(h, q); })) {
          covered = true;
          ++in_body;
          CHECK(chord > kEgoBodyMargin);
        }
      }
      if (chord > kEgoBodyMargin && (q - pose.position).norm() > 5.0) {
        ++hidden;
        hidden_covered += covered;
      }
      const Position local = to_local * (q - pose.position);
      bool beyond_view = false;
      for (int k = 0; k < regions.fov; ++k) beyond_view |= inside(regions.fov_outside[k], q);
      if (beyond_view) {
        ++in_fov_region;
        CHECK(OutsideFov(local, local.norm(), FovCosBound(half_fov)));
      }
      outside += std::abs(std::atan2(local.y(), local.x())) > half_fov + 1e-3 && half_fov < 1.5;
    }
  }
  INFO(in_body << " points in body regions; " << hidden_covered << " of " << hidden
               << " hidden points covered; " << in_fov_region << " of " << outside
               << " points outside the view in its regions");
  CHECK(in_body > 10000);
  CHECK(hidden_covered > 0.8 * static_cast<double>(hidden));
  CHECK(in_fov_region > 0.9 * static_cast<double>(outside));
}

// A box's shadow (BoxShadow): every point kCutDistance inside it must be hidden by the box as
// BehindOthers tests it (the line of sight shrunk by kOcclusionShrink hits the box, the point is
// farther than the occluder's min_distance, its direction passes the dot test);
// and the shadow must hold most points hidden by the box 0.5 m or more beyond it (fails if it is
// turned, empty or reaches past the box's outline).
TEST_CASE("a box's shadow lies behind the box", "[radar][edge_walk]") {
  std::size_t in_shadow = 0, behind = 0, behind_covered = 0;
  for (std::uint32_t scene = 0; scene < 300; ++scene) {
    CounterRng rng(47, RngPurpose::kTest, scene, 0);
    const OrientedBox box{Position(rng.Uniform(-30.0, 30.0), rng.Uniform(-30.0, 30.0)),
                          rng.Uniform(-kPi, kPi), rng.Uniform(0.5, 15.0), rng.Uniform(0.5, 3.0)};
    const Position s(rng.Uniform(-10.0, 10.0), rng.Uniform(-10.0, 10.0));
    const auto shadow = BoxShadow(s, box.Corners());
    if (box.Contains(s)) CHECK(!shadow);
    if (!shadow) continue;
    Occluder o;
    o.a = box.center;
    o.axis = UnitVector(box.yaw);
    o.half_length = 0.5 * box.length;
    o.half_width = 0.5 * box.width;
    Position relative[4];  // the box's angular interval as CullTargets computes it (frame of s)
    for (int k = 0; k < 4; ++k) relative[k] = box.Corners()[k] - s;
    const Interval interval = IntervalOf(relative, 4);
    // The occluder's min_distance as SensorScan::CullTargets sets it.
    const double nearest =
        std::max(0.0, (box.center - s).norm() - 0.5 * std::hypot(box.length, box.width));
    for (int i = 0; i < 300; ++i) {
      const Position q = s + rng.Uniform(0.0, 80.0) * UnitVector(rng.Uniform(-kPi, kPi));
      const double range = (q - s).norm();
      const Position end = q - kOcclusionShrink * (q - s) / range;
      const bool inside = std::all_of(shadow->begin(), shadow->end(), [&](const HalfPlane& h) {
        return h.n.dot(q) - h.offset >= kCutDistance;
      });
      if (inside) {
        ++in_shadow;
        CHECK(SegmentHitsBox(o, s, end));
        CHECK(range > nearest);
        CHECK((q - s).dot(UnitVector(interval.center)) / range >=
              std::cos(interval.half_width) - 1e-12);  // BehindOthers' dot test lists the box
      }
      // Hidden 0.5 m or more beyond the box: the line of sight still hits it 0.5 m short of q.
      if (SegmentHitsBox(o, s, q - 0.5 * (q - s) / range) && !box.Contains(q)) {
        ++behind;
        behind_covered += inside;
      }
    }
  }
  INFO(in_shadow << " points in shadows; " << behind_covered << " of " << behind << " covered");
  CHECK(in_shadow > 2000);
  CHECK(behind_covered > 0.8 * static_cast<double>(behind));
}
