#include <cmath>
#include <optional>
#include <set>
#include <vector>

#include <catch2/catch.hpp>

#include "dualgrid/core/random.hpp"
#include "dualgrid/eval/metrics.hpp"

using dualgrid::CounterRng;
using dualgrid::OrientedBox;
using dualgrid::Position;
using dualgrid::RngPurpose;
using dualgrid::Velocity;
using dualgrid::eval::Cluster;
using dualgrid::eval::ObjectMetrics;
using dualgrid::eval::ScenarioMetrics;
using dualgrid::eval::TrackingMetricsAccumulator;
using dualgrid::eval::TrackingMetricsParams;
using dualgrid::eval::TruthObject;

namespace {

constexpr double kDt = 0.05;  // 20 Hz
constexpr int kFrames = 40;

TruthObject Object(int id, int f, double length = 4.5) {
  TruthObject o;
  o.id = id;
  const Velocity v(25.0, 0.0);
  // Objects 50 m apart laterally so that no gate overlaps another object's.
  o.box = OrientedBox{Position(v.x() * f * kDt, 50.0 * id), 0.0, length, 1.8};
  o.velocity = v;
  o.in_grid = o.in_coverage = o.detected_in_grid = true;
  return o;
}

Cluster ClusterOn(const TruthObject& o, Position offset, Velocity velocity_offset) {
  Cluster c;
  c.position = o.box.center + offset;
  c.velocity = o.velocity + velocity_offset;
  c.size = 20;
  c.weight = 1.0;
  return c;
}

const ObjectMetrics& Find(const ScenarioMetrics& m, int id) {
  for (const ObjectMetrics& o : m.objects)
    if (o.id == id) return o;
  FAIL("object " << id << " missing");
  return m.objects.front();
}

// Object 3's tracked frames: 0..4 (before it enters coverage at frame 5), then the gappy start
// 6, 7, 9, 11, 12, 13, then 14..29 continuously, lost for 30..39.
bool Object3Tracked(int f) {
  static const std::set<int> gappy = {0, 1, 2, 3, 4, 6, 7, 9, 11, 12, 13};
  return gappy.count(f) > 0 || (f >= 14 && f <= 29);
}

ScenarioMetrics RunSyntheticScenario() {
  TrackingMetricsAccumulator acc;  // defaults: 4 of 5, min 20 frames, margin 1 m, gate 2.5 m
  for (int f = 0; f < kFrames; ++f) {
    std::vector<TruthObject> objects;
    std::vector<Cluster> clusters;
    // 1: tracked every frame, position error 0.5 m, velocity error 0.2 m/s.
    objects.push_back(Object(1, f));
    clusters.push_back(ClusterOn(objects.back(), {0.3, 0.4}, {0.0, 0.2}));
    // 2: in grid and coverage, never tracked.
    objects.push_back(Object(2, f));
    // 3: tracked with gaps, errors 1.0 m and 1.0 m/s; enters coverage at frame 5.
    objects.push_back(Object(3, f));
    objects.back().in_coverage = f >= 5;
    if (Object3Tracked(f)) clusters.push_back(ClusterOn(objects.back(), {0.6, 0.8}, {1.0, 0.0}));
    // 4: a 12 m truck split into a rear cluster (3.0 m behind the centre, matched, velocity
    // error 0.5 m/s) and a front cluster 3.5 m ahead (duplicate).
    objects.push_back(Object(4, f, 12.0));
    clusters.push_back(ClusterOn(objects.back(), {3.5, 0.0}, {0.0, 0.0}));
    clusters.push_back(ClusterOn(objects.back(), {-3.0, 0.0}, {0.3, 0.4}));
    // 5: in the grid only for frames 30..39 (10 < 20 frames: not scored), tracked exactly.
    if (f >= 30) {
      objects.push_back(Object(5, f));
      clusters.push_back(ClusterOn(objects.back(), {0.0, 0.0}, {0.0, 0.0}));
    }
    // 6: listed but never in the grid, with a cluster on it: neither scored nor false.
    objects.push_back(Object(6, f));
    objects.back().in_grid = objects.back().detected_in_grid = false;
    clusters.push_back(ClusterOn(objects.back(), {1.0, 0.0}, {5.0, 0.0}));
    // 7: in the grid but never seen by a radar.
    objects.push_back(Object(7, f));
    objects.back().in_coverage = false;
    // A false cluster far from everything in the first 20 frames.
    if (f < 20) {
      Cluster c;
      c.position = Position(500.0, -500.0);
      clusters.push_back(c);
    }
    acc.AddFrame(f * kDt, clusters, objects);
  }
  return acc.Result();
}

}  // namespace

TEST_CASE("Tracking metrics of a synthetic scenario equal the hand-computed values", "[metrics]") {
  const ScenarioMetrics m = RunSyntheticScenario();
  CHECK(m.frames == kFrames);
  // Tracked in-grid pairs: object 1: 40, object 3: 5 + 6 + 16 = 27, truck: 40, object 5: 10.
  CHECK(m.matches == 117);
  REQUIRE(m.position_error);
  CHECK(*m.position_error == Approx((40 * 0.5 + 27 * 1.0 + 40 * 3.0 + 10 * 0.0) / 117.0));
  REQUIRE(m.velocity_error);
  CHECK(*m.velocity_error == Approx((40 * 0.2 + 27 * 1.0 + 40 * 0.5 + 10 * 0.0) / 117.0));

  // D over the scored objects 1, 2, 3, 4, 7.
  CHECK(m.objects_scored == 5);
  REQUIRE(m.tracked_fraction);
  CHECK(*m.tracked_fraction == Approx((1.0 + 0.0 + 27.0 / 40.0 + 1.0 + 0.0) / 5.0));

  // t_d: object 1 and the truck are consistent at frame 3 with onset frame 0 (t_d = 0). Object 3:
  // clock starts at frame 5; windows ending at 9..12 hold 3 tracked frames, the window 9..13
  // holds 4 (9, 11, 12, 13), so onset = frame 9 and t_d = (9 - 5) * 0.05 = 0.2 s.
  CHECK(m.objects_detected == 3);
  REQUIRE(m.detection_time);
  CHECK(*m.detection_time == Approx((0.0 + 0.2 + 0.0) / 3.0));
  // Objects 2 and 7 were scored and never consistently tracked (both count: D includes them);
  // object 7 was never in any radar's coverage.
  CHECK(m.objects_never_tracked == 2);
  CHECK(m.objects_never_observable == 1);

  // Clusters: 40 + 27 + 80 + 10 + 40 + 20 = 217 over 40 scans; false only the far one (20).
  CHECK(m.clusters_per_scan == Approx(217.0 / 40.0));
  CHECK(m.false_clusters_per_scan == Approx(20.0 / 40.0));
  CHECK(m.duplicate_clusters_per_scan == Approx(1.0));

  // Per-object table: every object ever in the grid (not 6), ascending id.
  REQUIRE(m.objects.size() == 6);
  CHECK(m.objects[0].id == 1);
  CHECK(m.objects[5].id == 7);
  const ObjectMetrics& o2 = Find(m, 2);
  CHECK(o2.frames_in_grid == 40);
  CHECK(o2.frames_tracked == 0);
  CHECK(*o2.tracked_fraction == 0.0);
  CHECK_FALSE(o2.detection_time);
  CHECK_FALSE(o2.position_error);
  const ObjectMetrics& o3 = Find(m, 3);
  CHECK(o3.frames_tracked == 27);
  CHECK(*o3.tracked_fraction == Approx(27.0 / 40.0));
  CHECK(*o3.clock_start_time == Approx(0.25));
  CHECK(*o3.track_onset_time == Approx(0.45));
  CHECK(*o3.detection_time == Approx(0.2));
  CHECK(*o3.position_error == Approx(1.0));
  const ObjectMetrics& o4 = Find(m, 4);
  CHECK(*o4.tracked_fraction == 1.0);
  CHECK(*o4.position_error == Approx(3.0));
  CHECK(*o4.velocity_error == Approx(0.5));
  const ObjectMetrics& o5 = Find(m, 5);
  CHECK_FALSE(o5.scored);
  CHECK(o5.frames_in_grid == 10);
  CHECK(*o5.first_in_grid_time == Approx(1.5));
  CHECK(*o5.detection_time == Approx(0.0));  // defined, but not in the scenario mean
  const ObjectMetrics& o7 = Find(m, 7);
  CHECK(o7.scored);
  CHECK_FALSE(o7.clock_start_time);
}

TEST_CASE("ScenarioMetrics JSON round trip", "[metrics]") {
  ScenarioMetrics m = RunSyntheticScenario();
  dualgrid::eval::CellMetrics cells;
  cells.confusion[2][2] = 5;
  cells.cells = 5;
  cells.dynamic_f1 = 1.0;
  m.cells = cells;
  const nlohmann::json j = m;
  CHECK(j.at("objects").size() == 6);
  CHECK(j.at("objects").at(1).at("detection_time").is_null());
  const ScenarioMetrics back = j.get<ScenarioMetrics>();
  CHECK(nlohmann::json(back) == j);
  CHECK(*back.detection_time == *m.detection_time);
  REQUIRE(back.cells);
  CHECK(back.cells->confusion[2][2] == 5);
}

TEST_CASE("t_d and D agree with a direct window scan on random tracks", "[metrics]") {
  const std::uint64_t seed = GENERATE(range(1, 31));
  CounterRng rng(seed, RngPurpose::kTest, 0, 0);
  TrackingMetricsParams params;
  params.required = 1 + static_cast<int>(rng.Uniform() * 4);
  params.window = params.required + static_cast<int>(rng.Uniform() * 3);
  params.min_frames_in_grid = 1;
  const int frames = 60;
  const int coverage_from = static_cast<int>(rng.Uniform() * 20);
  const double p_track = rng.Uniform(0.2, 0.95);
  std::vector<bool> tracked(frames);
  for (int f = 0; f < frames; ++f) tracked[f] = rng.Uniform() < p_track;

  TrackingMetricsAccumulator acc(params);
  for (int f = 0; f < frames; ++f) {
    TruthObject o = Object(1, f);
    o.in_coverage = f >= coverage_from;
    std::vector<Cluster> clusters;
    if (tracked[f]) clusters.push_back(ClusterOn(o, {0.1, 0.0}, {0.0, 0.0}));
    acc.AddFrame(f * kDt, clusters, std::span<const TruthObject>(&o, 1));
  }
  const ScenarioMetrics m = acc.Result();

  // Direct definition: first frame f >= start whose window [max(start, f - n + 1), f] holds
  // >= k tracked frames; onset = first tracked frame of that window.
  std::optional<double> expected_td;
  for (int f = coverage_from; f < frames && !expected_td; ++f) {
    const int lo = std::max(coverage_from, f - params.window + 1);
    int count = 0, first = -1;
    for (int g = lo; g <= f; ++g) {
      if (!tracked[g]) continue;
      ++count;
      if (first < 0) first = g;
    }
    if (count >= params.required) expected_td = (first - coverage_from) * kDt;
  }
  int tracked_count = 0;
  for (const bool t : tracked) tracked_count += t;

  REQUIRE(m.tracked_fraction);
  CHECK(*m.tracked_fraction == Approx(tracked_count / static_cast<double>(frames)));
  CHECK(m.detection_time.has_value() == expected_td.has_value());
  if (expected_td) CHECK(*m.detection_time == Approx(*expected_td).margin(1e-12));
  CHECK(m.objects_never_tracked == (expected_td ? 0 : 1));
}

TEST_CASE("Metrics params validation and misuse", "[metrics]") {
  std::string error;
  CHECK(TrackingMetricsParams{}.IsValid(&error));
  TrackingMetricsParams p;
  p.required = 6;
  CHECK_FALSE(p.IsValid(&error));
  CHECK(error.find("required") != std::string::npos);
  p = {};
  p.association.center_gate = -1.0;
  CHECK_FALSE(p.IsValid(&error));
  CHECK(error.find("association.center_gate") != std::string::npos);
  p = {};
  p.min_frames_in_grid = 0;
  CHECK_FALSE(p.IsValid(&error));
  CHECK(error.find("min_frames_in_grid") != std::string::npos);

  const nlohmann::json pj = TrackingMetricsParams{};
  CHECK(pj.at("association").at("center_gate") == 2.5);
  CHECK(pj.at("required") == 4);

  TrackingMetricsAccumulator acc;
  const std::vector<TruthObject> twice = {Object(1, 0), Object(1, 0)};
  CHECK_THROWS_AS(acc.AddFrame(0.0, {}, twice), std::invalid_argument);
  acc.AddFrame(1.0, {}, {});
  CHECK_THROWS_AS(acc.AddFrame(1.0, {}, {}), std::invalid_argument);
  CHECK_THROWS_AS(acc.AddFrame(0.5, {}, {}), std::invalid_argument);
  const ScenarioMetrics empty = acc.Result();
  CHECK(empty.frames == 1);
  CHECK_FALSE(empty.position_error);
  CHECK_FALSE(empty.tracked_fraction);
  CHECK_FALSE(empty.detection_time);
}

TEST_CASE("Box distance: zero inside the box, the overshoot beyond a face outside", "[metrics]") {
  const double yaw = GENERATE(0.0, 0.7, -2.0);
  TrackingMetricsAccumulator acc;
  TruthObject o;
  o.id = 1;
  o.box = OrientedBox{Position(10, 5), yaw, 4.0, 2.0};
  o.in_grid = o.in_coverage = true;
  // Frame 1: 1.5 m ahead of the centre (inside). Frame 2: 3 m ahead (1 m beyond the front face).
  // Frame 3: 2.5 m ahead and 1.5 m to the left (0.5 m beyond both the front and the side face).
  const dualgrid::Vector2 fwd = dualgrid::UnitVector(yaw);
  const dualgrid::Vector2 left = dualgrid::UnitVector(yaw + dualgrid::kPi / 2);
  const std::vector<Position> at = {o.box.center + 1.5 * fwd, o.box.center + 3.0 * fwd,
                                    o.box.center + 2.5 * fwd + 1.5 * left};
  for (int f = 0; f < 3; ++f) {
    Cluster c;
    c.position = at[f];
    c.weight = 1.0;
    c.size = 10;
    acc.AddFrame(0.05 * (f + 1), std::vector<Cluster>{c}, std::vector<TruthObject>{o});
  }
  const ScenarioMetrics m = acc.Result();
  REQUIRE(m.box_distance);
  CHECK(*m.box_distance == Approx((0.0 + 1.0 + std::sqrt(0.5)) / 3.0));
  CHECK(*m.position_error == Approx((1.5 + 3.0 + std::hypot(2.5, 1.5)) / 3.0));
}

// D_v counts a tracked frame only when the cluster's velocity is right: within
// max(velocity_tolerance, velocity_tolerance_fraction x speed) of the object's.
TEST_CASE("D_v: right place with the wrong velocity is tracked for D, not for D_v",
          "[metrics][d_v]") {
  TrackingMetricsParams params;  // tolerance max(2 m/s, 20 % of 25 m/s = 5 m/s) = 5 m/s
  TrackingMetricsAccumulator acc(params);
  for (int f = 0; f < kFrames; ++f) {
    const TruthObject a = Object(1, f), b = Object(2, f);
    // Object 1: velocity 8 m/s off in the first half (wrong), 3 m/s off in the second (right).
    // Object 2: tracked at the right velocity only every fourth frame, else 6 m/s off.
    const std::vector<Cluster> clusters = {
        ClusterOn(a, Position(0.5, 0.0), Velocity(f < kFrames / 2 ? 8.0 : 3.0, 0.0)),
        ClusterOn(b, Position(0.0, 0.0), Velocity(0.0, f % 4 == 0 ? 1.0 : 6.0))};
    acc.AddFrame(f * kDt, clusters, std::vector<TruthObject>{a, b});
  }
  const ScenarioMetrics m = acc.Result();
  const ObjectMetrics& o1 = Find(m, 1);
  const ObjectMetrics& o2 = Find(m, 2);
  CHECK(*o1.tracked_fraction == Approx(1.0));
  CHECK(*o1.tracked_fraction_v == Approx(0.5));
  CHECK(o1.frames_tracked_v == kFrames / 2);
  CHECK(*o2.tracked_fraction == Approx(1.0));
  CHECK(*o2.tracked_fraction_v == Approx(0.25));
  CHECK(*m.tracked_fraction == Approx(1.0));
  CHECK(*m.tracked_fraction_v == Approx((0.5 + 0.25) / 2.0));

  // A slower object (5 m/s): the absolute bound (2 m/s) applies, so 3 m/s off is wrong too.
  TrackingMetricsAccumulator slow(params);
  for (int f = 0; f < kFrames; ++f) {
    TruthObject o = Object(1, f);
    o.velocity = Velocity(5.0, 0.0);
    slow.AddFrame(f * kDt, std::vector<Cluster>{ClusterOn(o, Position(0, 0), Velocity(3.0, 0))},
                  std::vector<TruthObject>{o});
  }
  CHECK(*slow.Result().tracked_fraction_v == Approx(0.0));
}

TEST_CASE("D_v tolerances are validated", "[metrics][d_v]") {
  TrackingMetricsParams p;
  p.velocity_tolerance = 0.0;
  std::string error;
  CHECK_FALSE(p.IsValid(&error));
  CHECK(error.find("velocity_tolerance") != std::string::npos);
  p = TrackingMetricsParams{};
  p.velocity_tolerance_fraction = 1.5;
  CHECK_FALSE(p.IsValid(&error));
  CHECK(error.find("velocity_tolerance_fraction") != std::string::npos);
}

// The t_d clock starts at the first detection in the grid (in coverage), and the consistent track
// needs the right velocity: a cluster on the object's front before its centre enters the grid
// counts from the first detection, and a wrong-velocity cluster does not end the clock.
TEST_CASE(
    "t_d: the clock starts at the first detection in the grid; onset needs the right "
    "velocity",
    "[metrics][t_d]") {
  TrackingMetricsAccumulator acc;
  for (int f = 0; f < kFrames; ++f) {
    // Object 1 (oncoming, say): detected in the grid from frame 4, its centre in the grid only
    // from frame 10; a cluster with the right velocity on it from frame 8.
    TruthObject a = Object(1, f);
    a.detected_in_grid = f >= 4;
    a.in_grid = f >= 10;
    // Object 2: detected and in the grid throughout; clusters from frame 0, but with a 9 m/s
    // velocity error until frame 12 (beyond max(2, 0.2 x 25 = 5) m/s), right from frame 12.
    const TruthObject b = Object(2, f);
    std::vector<Cluster> clusters;
    if (f >= 8) clusters.push_back(ClusterOn(a, {0.0, 0.0}, {0.5, 0.0}));
    clusters.push_back(ClusterOn(b, {0.0, 0.0}, {f < 12 ? 9.0 : 0.5, 0.0}));
    acc.AddFrame(f * kDt, clusters, std::vector<TruthObject>{a, b});
  }
  const ScenarioMetrics m = acc.Result();
  const ObjectMetrics& o1 = Find(m, 1);
  const ObjectMetrics& o2 = Find(m, 2);
  REQUIRE(o1.clock_start_time);
  CHECK(*o1.clock_start_time == Approx(4 * kDt));
  REQUIRE(o1.detection_time);
  CHECK(*o1.detection_time == Approx((8 - 4) * kDt));  // not 0: the front was shown at frame 4
  CHECK(o1.frames_in_grid == kFrames - 10);
  REQUIRE(o2.detection_time);
  CHECK(*o2.detection_time == Approx(12 * kDt));  // D counted it from frame 0, t_d does not
  CHECK(*o2.tracked_fraction == Approx(1.0));
}
