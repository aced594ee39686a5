// Multipath ghosts (docs/radar.md, "Multipath"): the mirror geometry, the ghosts' labels, extent,
// occlusion and Doppler, and their detection rates against the documented loss. One corner radar
// at the origin looking along +x, a guard rail along y = 5 m and a car on the other side of the
// sensor (centre y = -3 m): its mirror image lies at y = 13 m, seen through the rail at x ~ 8 m.
// Tolerances are derived in comments; statistical checks use 5 standard errors.
#include <catch2/catch.hpp>

#include <omp.h>
#include <cmath>
#include <vector>

#include "dualgrid/core/random.hpp"
#include "dualgrid/radar_model/radar_model.hpp"

using namespace dualgrid;
using namespace dualgrid::radar;

namespace {

constexpr int kCar = 7, kRail = 100, kTruck = 8, kWall = 9;
constexpr double kTiny = 0.005;  // [m] a point-like box: all its scatterers in one cell

SensorParams Sensor() {
  SensorParams p = DefaultShortRangeRadar();
  p.name = "test";
  return p;  // mount at the origin, boresight +x, fov 150 deg, 0.5-80 m
}

EgoMotion Ego(const Velocity& v = Velocity::Zero()) {
  EgoMotion ego;
  ego.velocity = v;  // no body: the sensor sits alone at the origin
  return ego;
}

ModelOptions Options(bool multipath, double rail_loss_db = 6.0) {
  ModelOptions o;
  o.noise = false;
  o.false_alarms = false;
  o.multipath.enabled = multipath;
  o.multipath.rail_loss_db = rail_loss_db;
  o.multipath.min_pd = 0.0;  // keep every ghost scatterer: the tests look at weak ones too
  return o;
}

Polyline Rail(double x0 = -50.0, double x1 = 100.0, double y = 5.0) {
  return {kRail, {{x0, y}, {x1, y}}, -5.0};
}

Target Car(const Position& c, const Velocity& v, double size = 0.0, double rcs = 10.0) {
  const double l = size > 0.0 ? size : 4.5, w = size > 0.0 ? size : 1.8;
  return {kCar, OrientedBox{c, 0.0, l, w}, v, 0.0, rcs};
}

Scene CarAndRail() {
  Scene scene;
  scene.targets.push_back(Car({20.0, -3.0}, {12.0, 0.0}));
  scene.polylines.push_back(Rail());
  return scene;
}

std::vector<Scatterer> Ghosts(const std::vector<Scatterer>& all, int source) {
  std::vector<Scatterer> out;
  for (const Scatterer& s : all)
    if (s.path != Path::kDirect && s.source_id == source) out.push_back(s);
  return out;
}

const Mirror kRailMirror{{0.0, 5.0}, {0.0, -1.0}, Velocity::Zero(), 0.0};  // normal to the sensor

}  // namespace

TEST_CASE("Mirror: the image of the image is the object, in position and velocity",
          "[radar][multipath][property]") {
  for (int i = 0; i < 200; ++i) {
    CounterRng rng(31, RngPurpose::kTest, 0, static_cast<std::uint32_t>(i));
    Mirror m;
    m.point = {rng.Uniform(-50, 50), rng.Uniform(-50, 50)};
    m.normal = UnitVector(rng.Uniform(-kPi, kPi));
    m.point_velocity = {rng.Uniform(-30, 30), rng.Uniform(-30, 30)};
    m.yaw_rate = rng.Uniform(-0.5, 0.5);
    const Position p(rng.Uniform(-80, 80), rng.Uniform(-80, 80));
    const Velocity v(rng.Uniform(-40, 40), rng.Uniform(-40, 40));
    const Position p1 = m.Image(p);
    const Velocity v1 = m.ImageVelocity(p, v);
    // Rounding: a few ulps of coordinates of ~100 m and speeds of ~100 m/s.
    CHECK((m.Image(p1) - p).norm() < 1e-11);
    CHECK((m.ImageVelocity(p1, v1) - v).norm() < 1e-11);
    CHECK(m.SignedDistance(p1) == Approx(-m.SignedDistance(p)).margin(1e-11));
    CHECK((p1 - m.point).norm() == Approx((p - m.point).norm()).margin(1e-11));
    // The image velocity is the time derivative of the image: central difference over +-h with
    // the mirror moving and turning (error O(h^2) times the second derivative, < 1e-4 m/s here).
    const double h = 1e-4;
    const auto image_at = [&](double t) {
      Mirror mt = m;
      mt.point = m.point + t * m.point_velocity;
      mt.normal = Rotation(m.yaw_rate * t) * m.normal;
      return mt.Image(p + t * v);
    };
    CHECK(((image_at(h) - image_at(-h)) / (2.0 * h) - v1).norm() < 1e-4);
  }
  // A static mirror: v' = v - 2 (v.n) n exactly as the issue writes it.
  const Velocity v(3.0, -4.0);
  CHECK((kRailMirror.ImageVelocity({7.0, -1.0}, v) - Velocity(3.0, 4.0)).norm() < 1e-15);
}

TEST_CASE("Ghosts are labelled, placed by their path and mirror back onto the object",
          "[radar][multipath]") {
  const RadarModel model({Sensor()}, Options(true), 1);
  const EgoMotion ego = Ego({15.0, 0.0});
  const std::vector<Scatterer> all = model.VisibleScatterers(0, ego, CarAndRail());
  const std::vector<Scatterer> ghosts = Ghosts(all, kCar);
  int order2[3] = {0, 0, 0}, order3 = 0;
  const OrientedBox car = CarAndRail().targets[0].box;
  const OrientedBox grown{car.center, car.yaw, car.length + 2e-6, car.width + 2e-6};
  for (const Scatterer& g : ghosts) {
    CHECK(g.reflector_id == kRail);
    // The real point is on the car (its boundary), the image of the origin.
    CHECK(grown.Contains(g.origin));
    const Position s = Position::Zero();
    const Position image = kRailMirror.Image(g.origin);
    const double d = g.origin.norm(), d_image = image.norm();
    const Velocity vs = ego.velocity;
    const Velocity vq = g.velocity, vq_image = kRailMirror.ImageVelocity(g.origin, vq);
    const double rr_direct = (vq - vs).dot(g.origin - s) / d;
    const double rr_image = (vq_image - vs).dot(image - s) / d_image;
    if (g.bounces == 3) {
      ++order3;
      CHECK(g.path == Path::kType2);
      // At the image, with the image's Doppler.
      CHECK((g.position - image).norm() < 1e-9);
      CHECK(g.truth.range == Approx(d_image).epsilon(1e-12));
      CHECK(g.truth.range_rate == Approx(rr_image).margin(1e-9));
    } else {
      REQUIRE(g.bounces == 2);
      ++order2[static_cast<int>(g.path)];
      // Range and Doppler: the means of the two legs; azimuth: the last leg's.
      CHECK(g.truth.range == Approx(0.5 * (d + d_image)).epsilon(1e-12));
      CHECK(g.truth.range_rate == Approx(0.5 * (rr_direct + rr_image)).margin(1e-9));
      const Position toward = g.path == Path::kType1 ? g.origin : image;
      CHECK(std::abs(WrapAngle(g.truth.azimuth - std::atan2(toward.y(), toward.x()))) < 1e-12);
      CHECK((g.position - g.truth.range * UnitVector(g.truth.azimuth)).norm() < 1e-9);
    }
  }
  // The car's rail-side face and corners: several scatterers of each path.
  CHECK(order3 >= 3);
  CHECK(order2[1] >= 3);
  CHECK(order2[1] == order2[2]);  // every order-2 scatterer arrives both ways
  // Nothing mirrors itself, and the direct returns are unchanged by the ghosts.
  const RadarModel off({Sensor()}, Options(false), 1);
  const std::vector<Scatterer> direct = off.VisibleScatterers(0, ego, CarAndRail());
  REQUIRE(direct.size() + ghosts.size() == all.size());
  for (std::size_t i = 0; i < direct.size(); ++i) {
    CHECK(all[i].path == Path::kDirect);
    CHECK((all[i].position - direct[i].position).norm() == 0.0);
    CHECK(all[i].rcs_m2 == direct[i].rcs_m2);
  }
}

TEST_CASE("A ghost vanishes without its reflector, off its extent, or with a leg hidden",
          "[radar][multipath]") {
  const RadarModel model({Sensor()}, Options(true), 1);
  const EgoMotion ego = Ego();
  REQUIRE_FALSE(Ghosts(model.VisibleScatterers(0, ego, CarAndRail()), kCar).empty());

  Scene no_rail = CarAndRail();
  no_rail.polylines.clear();
  CHECK(Ghosts(model.VisibleScatterers(0, ego, no_rail), kCar).empty());

  // The car's image is seen through the rail between x = 6.4 and 9.2 m (the rays to its image
  // corners); a rail ending at x = 5 m (or starting at 10 m) has no bounce point for it.
  for (const auto& [x0, x1] : {std::pair{-50.0, 5.0}, std::pair{10.0, 100.0}}) {
    Scene short_rail = CarAndRail();
    short_rail.polylines = {Rail(x0, x1)};
    CHECK(Ghosts(model.VisibleScatterers(0, ego, short_rail), kCar).empty());
  }

  // The sensor -> rail leg: a 6 m x 2 m box at (4, 2.5) crosses every ray to x in [6.4, 9.2] at
  // y = 5 (at x = 4 they are at y = 2.2 ... 3.1), and not the direct rays to the car (y < 0).
  Scene sensor_leg = CarAndRail();
  sensor_leg.targets.push_back(
      {kWall, OrientedBox{{4.0, 2.5}, 0.0, 6.0, 2.0}, Velocity::Zero(), 0.0, 10.0});
  CHECK(Ghosts(model.VisibleScatterers(0, ego, sensor_leg), kCar).empty());

  // The rail -> car leg: a 3 m x 4 m box at (13, 1.5) (y from -0.5 to 3.5) crosses every leg
  // from x in [6.4, 9.2] at y = 5 to the car's near face (y = -2.1), which pass x = 13 at
  // y = 0.9 ... 2.9; the direct rays to the car pass it at y < -1.9 and the sensor -> rail legs
  // end before x = 9.2.
  Scene object_leg = CarAndRail();
  object_leg.targets.push_back(
      {kWall, OrientedBox{{13.0, 1.5}, 0.0, 3.0, 4.0}, Velocity::Zero(), 0.0, 10.0});
  CHECK(Ghosts(model.VisibleScatterers(0, ego, object_leg), kCar).empty());
  // The car's direct returns are still there.
  int direct = 0;
  for (const Scatterer& s : model.VisibleScatterers(0, ego, object_leg))
    direct += s.path == Path::kDirect && s.source_id == kCar;
  CHECK(direct > 0);

  // Switched off: the rails as mirrors, or multipath as a whole.
  ModelOptions no_rails = Options(true);
  no_rails.multipath.rails = false;
  CHECK(Ghosts(RadarModel({Sensor()}, no_rails, 1).VisibleScatterers(0, ego, CarAndRail()), kCar)
            .empty());
  CHECK(Ghosts(RadarModel({Sensor()}, Options(false), 1).VisibleScatterers(0, ego, CarAndRail()),
               kCar)
            .empty());
}

TEST_CASE("A static object's ghost off a static rail: zero compensated Doppler at its image",
          "[radar][multipath][property]") {
  // A point-like parked box; the ego drives at 20 m/s. Order 3: the image is static, so its
  // compensated radial speed is 0 up to the box's angular extent (|v_s| 2 sin(delta)). Order 2:
  // the measured range rate is the mean of -v_s.u and -v_s.u', so the compensation along the
  // arrival direction leaves v_s.(u_arrival - u_other) / 2: not zero (docs/radar.md).
  const RadarModel model({Sensor()}, Options(true, 0.0), 1);
  const Velocity vs(20.0, 0.0);
  const EgoMotion ego = Ego(vs);
  const Position c(20.0, -3.0);
  Scene scene;
  scene.targets.push_back(Car(c, Velocity::Zero(), kTiny, 30.0));
  scene.polylines.push_back(Rail());
  const Position image = kRailMirror.Image(c);
  const Vector2 u = c.normalized(), u_image = image.normalized();
  const double delta = std::atan(kTiny / (c.norm() - kTiny));
  const double tol = vs.norm() * 2.0 * std::sin(delta) + 1e-9;
  int seen[3] = {0, 0, 0};
  for (const Detection& d : model.ScanSensor(0, ego, scene, 0)) {
    if (d.path == Path::kDirect) {
      CHECK(std::abs(d.radial_speed_compensated) <= tol);
      continue;
    }
    CHECK(d.source_id == -1);  // a ghost is never its object
    CHECK(d.ghost_of == kCar);
    CHECK(d.reflector_id == kRail);
    CHECK_FALSE(d.is_clutter);
    if (d.bounces == 3) {
      ++seen[0];
      CHECK(std::abs(d.radial_speed_compensated) <= tol);
      CHECK((d.position_world - image).norm() < 2.0 * kTiny);
    } else {
      const bool type1 = d.path == Path::kType1;
      ++seen[type1 ? 1 : 2];
      const double expected = 0.5 * vs.dot(type1 ? u - u_image : u_image - u);
      CHECK(std::abs(d.radial_speed_compensated - expected) <= 2.0 * tol);
      CHECK(std::abs(expected) > 1.0);  // the formula is tested on a real offset
    }
  }
  CHECK(seen[0] == 1);
  CHECK(seen[1] == 1);
  CHECK(seen[2] == 1);
}

TEST_CASE("Ghost SNR and detection rate follow the documented loss per bounce",
          "[radar][multipath][statistics]") {
  // A point-like car whose order-3 ghost is detected with Pd 0.5 at loss L: its SNR is the
  // direct SNR at the image's range minus 2 L, the order-2 ghosts' G sigma Gamma / (d^2 d'^2).
  const SensorParams p = Sensor();
  const SensorModel sm(p);
  const Position c(20.0, -3.0), image = kRailMirror.Image(c);
  const double loss = GENERATE(0.0, 6.0, 12.0);
  const double snr_half = RequiredSnr(0.5, p.false_alarm_rate);
  const double rcs_dbsm = 10.0 * std::log10(snr_half) - sm.SnrDb(0.0, image.norm()) + 2.0 * loss;
  Scene scene;
  scene.targets.push_back(Car(c, {5.0, 0.0}, kTiny, rcs_dbsm));
  scene.polylines.push_back(Rail());
  const RadarModel model({p}, Options(true, loss), 3);
  const double expected3 = sm.SnrDb(rcs_dbsm, image.norm()) - 2.0 * loss;
  const double expected2 = sm.SnrDb(rcs_dbsm, 1.0) - loss - 20.0 * std::log10(c.norm()) -
                           20.0 * std::log10(image.norm());
  // The expectations use the box centre; its scatterers lie up to kTiny from it, closer to the
  // sensor by at most that: 40 log10(R / (R - kTiny)) dB more, at the nearest leg (the car).
  const double snr_tol = 40.0 * std::log10(c.norm() / (c.norm() - kTiny));
  constexpr int kScans = 4000;
  int hits3 = 0, hits2 = 0;
  for (int step = 0; step < kScans; ++step) {
    for (const Detection& d : model.ScanSensor(0, Ego(), scene, step)) {
      if (d.path == Path::kDirect) continue;
      if (d.bounces == 3) {
        ++hits3;
        CHECK(d.snr_db == Approx(expected3).margin(snr_tol));
      } else if (d.path == Path::kType2) {
        ++hits2;
        CHECK(d.snr_db == Approx(expected2).margin(snr_tol));
      }
    }
  }
  const auto within = [](int hits, double pd) {
    const double se = std::sqrt(pd * (1.0 - pd) / kScans);
    return std::abs(static_cast<double>(hits) / kScans - pd) <= 5.0 * se + 1e-12;
  };
  CHECK(within(hits3, DetectionProbability(std::pow(10.0, 0.1 * expected3), p.false_alarm_rate)));
  CHECK(within(hits2, DetectionProbability(std::pow(10.0, 0.1 * expected2), p.false_alarm_rate)));
  // Half the power per extra bounce: the rate of the order-3 ghost at Pd 0.5 is the test's
  // design, so a loss not applied (or applied once) would show as Pd ~ 1.
  CHECK(within(hits3, 0.5));
}

TEST_CASE("Ghosts thin out with range", "[radar][multipath][statistics]") {
  // The same car ever farther along x: its order-3 ghost's SNR falls as the image range^-4, and
  // its detection rate with it (monotone, each rate within 5 standard errors of its Pd).
  const SensorParams p = Sensor();
  const RadarModel model({p}, Options(true), 5);
  double last_pd = 1.0;
  for (const double x : {10.0, 30.0, 50.0, 70.0}) {
    Scene scene;
    scene.targets.push_back(Car({x, -3.0}, {5.0, 0.0}, kTiny, 0.0));
    scene.polylines.push_back(Rail(-50.0, 200.0));
    const double snr = SensorModel(p).SnrLinear(std::pow(10.0, 0.1 * (0.0 - 12.0)),
                                                kRailMirror.Image({x, -3.0}).norm());
    const double pd = DetectionProbability(snr, p.false_alarm_rate);
    constexpr int kScans = 2000;
    int hits = 0;
    for (int step = 0; step < kScans; ++step)
      for (const Detection& d : model.ScanSensor(0, Ego(), scene, step)) hits += d.bounces == 3;
    CHECK(std::abs(static_cast<double>(hits) / kScans - pd) <=
          5.0 * std::sqrt(pd * (1.0 - pd) / kScans) + 1e-12);
    CHECK(pd <= last_pd);
    last_pd = pd;
  }
  CHECK(last_pd < 0.05);
}

TEST_CASE("A truck's flank mirrors; a van's does not; a moving mirror shifts the Doppler",
          "[radar][multipath]") {
  // A 14 m truck beside the sensor (centre (12, 6), flank at y = 4.725 from x = 5 to 19) driving
  // at 25 m/s, and the car on the other side (its image is seen through x = 6.3 ... 9.1 on the
  // flank). The flank moves along itself: u.n = 0, so the image velocity is the static
  // formula's; a flank drifting towards the sensor at 1 m/s moves the image at -2 m/s in y.
  ModelOptions o = Options(true);
  o.multipath.rails = false;
  for (const double drift : {0.0, 1.0}) {
    Scene scene;
    scene.targets.push_back(Car({20.0, -3.0}, {12.0, 0.0}));
    scene.targets.push_back(
        {kTruck, OrientedBox{{12.0, 6.0}, 0.0, 14.0, 2.55}, {25.0, -drift}, 0.0, 25.0});
    const std::vector<Scatterer> ghosts =
        Ghosts(RadarModel({Sensor()}, o, 1).VisibleScatterers(0, Ego(), scene), kCar);
    REQUIRE_FALSE(ghosts.empty());
    const Mirror flank{{12.0, 6.0 - 0.5 * 2.55}, {0.0, -1.0}, {25.0, -drift}, 0.0};
    for (const Scatterer& g : ghosts) {
      CHECK(g.reflector_id == kTruck);
      if (g.bounces != 3) continue;
      const Velocity v_image = flank.ImageVelocity(g.origin, g.velocity);
      CHECK((v_image - Velocity(12.0, -2.0 * drift)).norm() < 1e-12);
      CHECK(g.truth.range_rate == Approx(v_image.dot(g.position.normalized())).margin(1e-9));
    }
    // A van (5.9 m, below vehicle_min_length) at the same place mirrors nothing.
    scene.targets[1].box.length = 5.9;
    CHECK(Ghosts(RadarModel({Sensor()}, o, 1).VisibleScatterers(0, Ego(), scene), kCar).empty());
  }
}

TEST_CASE("Multipath on without mirrors changes nothing; on, it is thread-count independent",
          "[radar][multipath][determinism]") {
  ModelOptions noisy;  // noise and clutter on: the random streams must line up
  noisy.multipath.enabled = true;
  const std::vector<SensorParams> rig = DefaultRig(4.5, 1.8);
  const RadarModel on(rig, noisy, 9), off(rig, ModelOptions{}, 9);
  EgoMotion ego;
  ego.velocity = {25.0, 0.0};
  ego.length = 4.5;
  ego.width = 1.8;
  Scene cars;
  for (int i = 0; i < 12; ++i) {
    cars.targets.push_back(Car({-40.0 + 8.0 * i, (i % 3 - 1) * 3.5}, {20.0 + i, 0.0}));
    cars.targets.back().id = 10 + i;
  }
  const auto same = [](const std::vector<Detection>& a, const std::vector<Detection>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
      if (a[i].range != b[i].range || a[i].azimuth != b[i].azimuth ||
          a[i].range_rate != b[i].range_rate || a[i].snr_db != b[i].snr_db ||
          a[i].source_id != b[i].source_id || a[i].path != b[i].path ||
          a[i].reflector_id != b[i].reflector_id)
        return false;
    return true;
  };
  // No rail, no truck: no mirror, the same detections bit for bit.
  CHECK(same(on.Scan(ego, cars, 4, 0.0, 0.05), off.Scan(ego, cars, 4, 0.0, 0.05)));
  // With rails and a truck: the same whatever the thread count.
  Scene mirrors = cars;
  mirrors.polylines.push_back({200, {{-200.0, 7.0}, {200.0, 7.0}}, -5.0});
  mirrors.polylines.push_back({201, {{-200.0, -7.0}, {200.0, -7.0}}, -5.0});
  mirrors.targets.push_back(
      {300, OrientedBox{{6.0, 3.5}, 0.0, 14.0, 2.55}, {26.0, 0.0}, 0.0, 25.0});
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const std::vector<Detection> one = on.Scan(ego, mirrors, 4, 0.0, 0.05);
  omp_set_num_threads(2);
  const std::vector<Detection> two = on.Scan(ego, mirrors, 4, 0.0, 0.05);
  omp_set_num_threads(threads);
  CHECK(same(one, two));
  int ghosts = 0;
  for (const Detection& d : one) ghosts += d.path != Path::kDirect;
  CHECK(ghosts > 0);
}

TEST_CASE("Multipath parameters are validated, naming the field", "[radar][multipath]") {
  MultipathParams ok;
  std::string error;
  CHECK(ok.IsValid(&error));
  const auto fails = [](MultipathParams m, const char* field) {
    std::string e;
    return !m.IsValid(&e) && e.rfind(field, 0) == 0;
  };
  MultipathParams m;
  m.rail_loss_db = -1.0;
  CHECK(fails(m, "rail_loss_db"));
  m = {};
  m.vehicle_loss_db = std::nan("");
  CHECK(fails(m, "vehicle_loss_db"));
  m = {};
  m.vehicle_min_length = 0.0;
  CHECK(fails(m, "vehicle_min_length"));
  m = {};
  m.max_bounces = 4;
  CHECK(fails(m, "max_bounces"));
  m = {};
  m.min_pd = 0.5;
  CHECK(fails(m, "min_pd"));
  ModelOptions o;
  o.multipath.max_bounces = 1;
  CHECK_THROWS_WITH(RadarModel({Sensor()}, o, 1), Catch::Contains("multipath.max_bounces"));
  CHECK(ToString(Path::kDirect) == "direct");
  CHECK(ToString(Path::kType1) == "type1");
  CHECK(ToString(Path::kType2) == "type2");
}
