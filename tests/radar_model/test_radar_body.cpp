// The ego's own body hides what lies behind it from its corner radars, and a face seen exactly
// edge-on returns nothing (docs/radar.md, steps 2 and 5).
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <vector>

#include "../../radar_model/src/scan_geometry.hpp"
#include "dualgrid/core/random.hpp"
#include "dualgrid/radar_model/radar_model.hpp"

using namespace dualgrid;
using namespace dualgrid::radar;

namespace {

constexpr double kEgoLength = 4.5, kEgoWidth = 1.8;

int SensorIndex(const std::vector<SensorParams>& rig, const std::string& name) {
  for (std::size_t i = 0; i < rig.size(); ++i)
    if (rig[i].name == name) return static_cast<int>(i);
  FAIL("no sensor " << name);
  return -1;
}

// Length of the part of segment a -> b inside the axis-aligned box |x| <= hl, |y| <= hw, by
// walking it in 1 mm steps (independent of the model's slab clipping).
double InsideLength(const Position& a, const Position& b, double hl, double hw) {
  const double len = (b - a).norm();
  const int steps = static_cast<int>(len / 1e-3) + 1;
  int inside = 0;
  for (int i = 0; i < steps; ++i) {
    const Position p = a + (i + 0.5) / steps * (b - a);
    inside += std::abs(p.x()) < hl && std::abs(p.y()) < hw;
  }
  return inside * len / steps;
}

}  // namespace

TEST_CASE("the ego's body hides targets from the corner radars behind it", "[radar][body]") {
  // A truck in the left lane ahead: front_right (at the front right wheel, looking -45 deg) sees
  // it only through the ego's front (its line of sight runs ~1 m inside the body).
  const auto rig = DefaultRig(kEgoLength, kEgoWidth);
  const RadarModel model(rig, ModelOptions{false, false, true, {}}, 1);
  Scene scene;
  scene.targets.push_back({1, OrientedBox{{10.0, 3.5}, 0.0, 12.0, 2.5}, {25, 0}, 0.0, 20.0});
  EgoMotion ghost;  // no body: the old model
  ghost.velocity = {25, 0};
  EgoMotion ego = ghost;
  ego.length = kEgoLength;
  ego.width = kEgoWidth;
  const int fr = SensorIndex(rig, "front_right"), fl = SensorIndex(rig, "front_left");
  REQUIRE(!model.VisibleScatterers(fr, ghost, scene).empty());  // not vacuous
  CHECK(model.VisibleScatterers(fr, ego, scene).empty());
  // The front_left radar, on the truck's side, still sees it.
  CHECK(!model.VisibleScatterers(fl, ego, scene).empty());
  // Occlusion off: the body is transparent too (ModelOptions::occlusion switches every occluder).
  const RadarModel open(rig, ModelOptions{false, false, false, {}}, 1);
  CHECK(!open.VisibleScatterers(fr, ego, scene).empty());
}

TEST_CASE("no visible scatterer's line of sight runs through the ego's body",
          "[radar][body][property]") {
  // Small targets all around the ego (rings of 3-30 m): every scatterer any sensor reports has a
  // line of sight at most 5 cm (the model's margin) + 2 mm (the 1 mm walk) inside the body less
  // its 1 mm skin (a line along the surface grazes it).
  const auto rig = DefaultRig(kEgoLength, kEgoWidth);
  const RadarModel model(rig, ModelOptions{false, false, true, {}}, 1);
  EgoMotion ego;
  ego.length = kEgoLength;
  ego.width = kEgoWidth;
  Scene scene;
  int id = 0;
  for (double r : {3.0, 6.0, 12.0, 30.0})
    for (int k = 0; k < 36; ++k)
      scene.targets.push_back(
          {id++, OrientedBox{r * UnitVector(k * kPi / 18.0), 0.3, 0.5, 0.5}, {0, 0}, 0.0, 20.0});
  std::size_t seen = 0;
  double worst = 0.0;
  for (int s = 0; s < static_cast<int>(rig.size()); ++s) {
    const Position origin = SensorWorldPose(rig[s], ego.pose).position;
    for (const Scatterer& sc : model.VisibleScatterers(s, ego, scene)) {
      ++seen;
      worst = std::max(worst, InsideLength(origin, sc.position, 0.5 * kEgoLength - 1e-3,
                                           0.5 * kEgoWidth - 1e-3));
    }
  }
  // Not vacuous: without the body the same sensors report more (those seen through it).
  EgoMotion ghost;
  std::size_t seen_through = 0;
  for (int s = 0; s < static_cast<int>(rig.size()); ++s)
    seen_through += model.VisibleScatterers(s, ghost, scene).size();
  INFO("scatterers " << seen << " (" << seen_through << " without the body), deepest line of "
                     << "sight inside the body " << worst << " m");
  CHECK(seen > 100);
  CHECK(seen_through > seen);
  CHECK(worst <= 0.052);
}

TEST_CASE("a flank seen exactly edge-on hides its far corner", "[radar][body]") {
  // A car ahead in the ego's lane, as wide as the ego: its right flank lies on the line y = -0.9
  // through the front_right radar. Only its rear face (x = 17.75) faces the sensor; the flank's
  // far corner (x = 22.25) is behind the near one and must not be reported (it was: 4.5 m behind
  // the visible face, simple road seed 1). No ego body here: it would hide this line of sight
  // (along its own flank) as well, and the test is of the edge-on rule alone.
  const auto rig = DefaultRig(kEgoLength, kEgoWidth);
  const RadarModel model(rig, ModelOptions{false, false, true, {}}, 1);
  const EgoMotion ego;
  // The flank offset by +-1 um from the sensors' lines (as rounding puts it in a simulation):
  // edge-on in effect, with the sensor in front of it by a hair on one side.
  Scene scene;
  for (const double offset : {1e-6, -1e-6, 0.0}) {
    scene.targets = {{1, OrientedBox{{20.0, offset}, 0.0, 4.5, 1.8}, {20, 0}, 0.0, 10.0}};
    for (const char* name : {"front_right", "front_left"}) {
      const auto visible = model.VisibleScatterers(SensorIndex(rig, name), ego, scene);
      REQUIRE(!visible.empty());
      for (const Scatterer& sc : visible) {
        INFO(name << " offset " << offset << ": scatterer at " << sc.position.transpose());
        CHECK(sc.position.x() <= 17.75 + 1e-9);
      }
    }
  }
  // A flank turned 2 deg towards the sensor (clockwise) is visible again (the tolerance is
  // 0.5 deg).
  scene.targets[0].box.yaw = DegToRad(-2.0);
  bool flank = false;
  for (const Scatterer& sc : model.VisibleScatterers(SensorIndex(rig, "front_right"), ego, scene))
    flank = flank || sc.position.x() > 18.5;
  CHECK(flank);
}

namespace {

// Share of scans with at least one detection of a 10 dBsm car (4.5 m x 1.8 m) seen from behind,
// its centre at `range` along sensor `name`'s boresight; noise on, no clutter.
double CarDetectionRate(const std::string& name, double range, int scans) {
  const auto rig = DefaultRig(kEgoLength, kEgoWidth);
  const RadarModel model(rig, ModelOptions{true, false, true, {}}, 3);
  const int s = SensorIndex(rig, name);
  EgoMotion ego;
  ego.length = kEgoLength;
  ego.width = kEgoWidth;
  const Pose2 sensor = SensorWorldPose(rig[s], ego.pose);
  Scene scene;
  scene.targets.push_back(
      {1, OrientedBox{sensor.position + range * UnitVector(sensor.yaw), sensor.yaw, 4.5, 1.8},
       Velocity::Zero(), 0.0, 10.0});
  int hit = 0;
  for (int k = 0; k < scans; ++k) {
    bool any = false;
    for (const Detection& d : model.ScanSensor(s, ego, scene, static_cast<std::uint64_t>(k)))
      any = any || d.source_id == 1;
    hit += any;
  }
  return static_cast<double>(hit) / scans;
}

}  // namespace

TEST_CASE("a car at the data-sheet range is detected in the documented share of scans",
          "[radar][detection]") {
  // docs/radar.md ("Detection range"): reference_pd = 0.9 is the probability for a point
  // scatterer of reference_rcs_dbsm (10 dBsm) at reference_range. A car's 10 dBsm are spread
  // over its visible corners and face samples, several resolution cells, each weaker than the
  // point: the share of scans with >= 1 detection of the car at the data-sheet range is lower.
  // Documented (measured with this test, 2,000 scans each): corner radar at 77.5 m 0.78, front
  // radar at 167 m 0.77; the band is 5 binomial standard errors, 5 sqrt(p (1 - p) / n) = 0.047.
  const int n = 2000;
  const double corner = CarDetectionRate("front_left", 77.5, n);
  const double front = CarDetectionRate("front", 167.0, n);
  INFO("P(>= 1 detection per scan): corner at 77.5 m " << corner << ", front at 167 m " << front);
  CHECK(std::abs(corner - 0.78) < 5.0 * std::sqrt(0.78 * 0.22 / n));
  CHECK(std::abs(front - 0.77) < 5.0 * std::sqrt(0.77 * 0.23 / n));
  // Closer in, the car is detected (almost) every scan: the data-sheet range is where it fades.
  CHECK(CarDetectionRate("front_left", 40.0, 500) > 0.98);
}

TEST_CASE("the radar model is rotation invariant", "[radar][body][property]") {
  // A road scene in the ego's frame: a car straight ahead in the ego's lane as wide as the ego
  // (its flanks continue the ego's: lines of sight along the ego's surface), a car in the next
  // lane, an oncoming car, a parked car and a guard rail. Turned about the world origin by
  // `deg`, every sensor must see the same scatterers (positions turned back within 1e-6 m), as
  // it must for roads in any direction. Exact geometry (no noise, no clutter); the grazing cases
  // at the ego's surface used to depend on rounding: seen at 45 deg, not at 0 deg.
  const auto rig = DefaultRig(kEgoLength, kEgoWidth);
  const RadarModel model(rig, ModelOptions{false, false, true, {}}, 1);
  const Position ego_at(312.5, -41.0);
  auto build = [&](double deg, EgoMotion* ego, Scene* scene) {
    const Pose2 turn{Position::Zero(), DegToRad(deg)};
    const auto place = [&](double x, double y) { return turn.ToParent(ego_at + Position(x, y)); };
    const double yaw = turn.yaw;
    ego->pose = {place(0, 0), yaw};
    ego->velocity = turn.RotateToParent(Velocity(20.0, 0.0));
    ego->length = kEgoLength;
    ego->width = kEgoWidth;
    scene->targets = {
        {1, OrientedBox{place(35.0, 0.0), yaw, 4.5, 1.8}, turn.RotateToParent({18.0, 0.0}), 0.0,
         10.0},
        {2, OrientedBox{place(12.0, 3.2), yaw, 4.5, 1.8}, turn.RotateToParent({25.0, 0.0}), 0.0,
         10.0},
        {3, OrientedBox{place(60.0, 6.4), WrapAngle(yaw + kPi), 5.9, 2.0},
         turn.RotateToParent({-22.0, 0.0}), 0.0, 14.0},
        {4, OrientedBox{place(25.0, -4.5), yaw, 4.5, 1.8}, Velocity::Zero(), 0.0, 10.0}};
    scene->polylines = {{5, {place(-80.0, -6.0), place(150.0, -6.0)}, -5.0}};
  };
  EgoMotion ego0;
  Scene scene0;
  build(0.0, &ego0, &scene0);
  for (const double deg : {30.0, 45.0, 90.0, 135.0, 210.0, 17.3, -63.9}) {
    EgoMotion ego;
    Scene scene;
    build(deg, &ego, &scene);
    const Pose2 back{Position::Zero(), -DegToRad(deg)};
    for (int s = 0; s < static_cast<int>(rig.size()); ++s) {
      const auto a = model.VisibleScatterers(s, ego0, scene0);
      const auto b = model.VisibleScatterers(s, ego, scene);
      INFO("turned by " << deg << " deg, sensor " << rig[s].name);
      REQUIRE(a.size() == b.size());
      for (std::size_t k = 0; k < a.size(); ++k) {
        CHECK(a[k].source_id == b[k].source_id);
        CHECK((back.ToParent(b[k].position) - a[k].position).norm() < 1e-6);
      }
    }
  }
  // Not vacuous: the car ahead is seen by the flank's corner radar along the ego's surface.
  bool lead_front_left = false;
  for (const auto& sc : model.VisibleScatterers(SensorIndex(rig, "front_left"), ego0, scene0))
    lead_front_left = lead_front_left || sc.source_id == 1;
  CHECK(lead_front_left);
}

TEST_CASE("the body hides exactly its points: the scan with it is the scan without, filtered",
          "[radar][body][property]") {
  // The scan tests the ego's body before the azimuth (VisibleScatterers' consider_kept); every
  // test is pure and must pass, so with the body each sensor reports the scatterers it reports
  // without it, minus those whose line of sight runs more than the margin inside the body, in
  // the same order and bit for bit. Random targets around the ego, rails on both sides, a turned
  // and moving ego.
  const auto rig = DefaultRig(kEgoLength, kEgoWidth);
  const RadarModel model(rig, ModelOptions{false, false, true, {}}, 1);
  const std::uint64_t seed = GENERATE(range(1, 6));
  CounterRng rng(seed, RngPurpose::kTest, 0, 0);
  EgoMotion ghost;  // no body
  ghost.pose = {{rng.Uniform(-50.0, 50.0), rng.Uniform(-50.0, 50.0)}, rng.Uniform(-kPi, kPi)};
  ghost.velocity = 20.0 * UnitVector(ghost.pose.yaw);
  EgoMotion ego = ghost;
  ego.length = kEgoLength;
  ego.width = kEgoWidth;
  Scene scene;
  for (int k = 0; k < 30; ++k) {
    const Position c =
        ghost.pose.position + rng.Uniform(3.0, 60.0) * UnitVector(rng.Uniform(-kPi, kPi));
    scene.targets.push_back(
        {k,
         OrientedBox{c, rng.Uniform(-kPi, kPi), rng.Uniform(1.0, 12.0), rng.Uniform(0.5, 2.5)},
         {rng.Uniform(-5.0, 5.0), rng.Uniform(-5.0, 5.0)},
         0.0,
         10.0});
  }
  const Vector2 along = UnitVector(ghost.pose.yaw), across(-along.y(), along.x());
  for (const double side : {-8.0, 8.0})
    scene.polylines.push_back({100 + static_cast<int>(side),
                               {ghost.pose.position - 150.0 * along + side * across,
                                ghost.pose.position + 150.0 * along + side * across}});
  radar::detail::Occluder body;
  body.a = ego.pose.position;
  body.axis = UnitVector(ego.pose.yaw);
  body.half_length = 0.5 * ego.length - radar::detail::kEgoBodySkin;
  body.half_width = 0.5 * ego.width - radar::detail::kEgoBodySkin;
  std::size_t hidden = 0, seen = 0;
  for (int s = 0; s < static_cast<int>(rig.size()); ++s) {
    const Position origin = model.SensorPose(s, ego.pose).position;
    std::vector<Scatterer> expected;
    for (const Scatterer& sc : model.VisibleScatterers(s, ghost, scene)) {
      if (radar::detail::LengthInsideBox(body, origin, sc.position) > radar::detail::kEgoBodyMargin)
        ++hidden;
      else
        expected.push_back(sc);
    }
    const std::vector<Scatterer> got = model.VisibleScatterers(s, ego, scene);
    REQUIRE(got.size() == expected.size());
    seen += got.size();
    for (std::size_t i = 0; i < got.size(); ++i) {
      INFO("sensor " << s << " scatterer " << i);
      CHECK(std::memcmp(&got[i].position, &expected[i].position, sizeof(Position)) == 0);
      CHECK(std::memcmp(&got[i].truth, &expected[i].truth, sizeof(Polar)) == 0);
      CHECK(std::memcmp(&got[i].rcs_m2, &expected[i].rcs_m2, sizeof(double)) == 0);
      CHECK(got[i].source_id == expected[i].source_id);
    }
  }
  INFO("seen " << seen << ", hidden by the body " << hidden);
  CHECK(seen > 100);  // not vacuous: both kinds occur
  CHECK(hidden > 10);
}
