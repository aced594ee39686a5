#include <catch2/catch.hpp>

#include <cmath>
#include <functional>
#include <string>

#include "dualgrid/radar_model/radar_model.hpp"

using namespace dualgrid;
using namespace dualgrid::radar;

TEST_CASE("Default rig: five valid sensors at the wheel positions and the front", "[radar]") {
  const double length = GENERATE(3.5, 4.5, 12.0);
  const double width = GENERATE(1.6, 2.5);
  const std::vector<SensorParams> rig = DefaultRig(length, width);
  REQUIRE(rig.size() == 5);
  const char* names[] = {"front_left", "front_right", "rear_left", "rear_right", "front"};
  for (std::size_t i = 0; i < rig.size(); ++i) {
    std::string error;
    CHECK(rig[i].IsValid(&error));
    CHECK(error.empty());
    CHECK(rig[i].name == names[i]);
  }
  // Corner radars face diagonally outwards from the wheel positions; all inside the ego box.
  const OrientedBox ego{Position::Zero(), 0.0, length, width};
  for (int i = 0; i < 4; ++i) {
    const Pose2& m = rig[i].mount;
    CHECK(ego.Contains(m.position));
    CHECK(std::abs(m.position.y()) == Approx(0.5 * width));
    CHECK(std::cos(m.yaw) * m.position.x() > 0.0);  // front ones face forward, rear ones back
    CHECK(std::sin(m.yaw) * m.position.y() > 0.0);  // left ones face left, right ones right
    CHECK(std::abs(std::abs(m.yaw) - DegToRad(90.0)) == Approx(DegToRad(45.0)));
    CHECK(rig[i].fov == Approx(DegToRad(150.0)));
  }
  CHECK(rig[4].mount.position.x() == Approx(0.5 * length));
  CHECK(rig[4].mount.yaw == 0.0);
  CHECK(rig[4].fov < DegToRad(25.0));
  CHECK(rig[4].max_range > 150.0);
}

TEST_CASE("DefaultRig rejects non-positive ego dimensions", "[radar]") {
  CHECK_THROWS_AS(DefaultRig(-4.5, 1.8), std::invalid_argument);
  CHECK_THROWS_AS(DefaultRig(4.5, 0.0), std::invalid_argument);
}

namespace {
void Profile(SensorParams& p, std::vector<double> at, std::vector<double> resolution,
             std::vector<double> accuracy) {
  p.off_boresight = std::move(at);
  p.off_boresight_resolution = std::move(resolution);
  p.off_boresight_accuracy = std::move(accuracy);
}
}  // namespace

TEST_CASE("Invalid sensor parameters are rejected naming the field", "[radar][params]") {
  using Mutate = std::function<void(SensorParams&)>;
  const auto [field, mutate] = GENERATE(table<std::string, Mutate>({
      {"name", [](SensorParams& p) { p.name.clear(); }},
      {"mount", [](SensorParams& p) { p.mount.yaw = std::nan(""); }},
      {"fov", [](SensorParams& p) { p.fov = DegToRad(361.0); }},
      {"fov", [](SensorParams& p) { p.fov = 0.0; }},
      {"min_range", [](SensorParams& p) { p.min_range = -1.0; }},
      {"max_range", [](SensorParams& p) { p.max_range = -80.0; }},
      {"max_range", [](SensorParams& p) { p.max_range = p.min_range; }},
      {"max_range_rate", [](SensorParams& p) { p.max_range_rate = p.min_range_rate - 1.0; }},
      {"range_resolution", [](SensorParams& p) { p.range_resolution = 0.0; }},
      {"range_resolution", [](SensorParams& p) { p.range_resolution = 1e-6; }},
      {"azimuth_resolution", [](SensorParams& p) { p.azimuth_resolution = -0.1; }},
      {"range_rate_resolution", [](SensorParams& p) { p.range_rate_resolution = 0.0; }},
      {"range_accuracy", [](SensorParams& p) { p.range_accuracy = -0.1; }},
      {"azimuth_accuracy", [](SensorParams& p) { p.azimuth_accuracy = -0.1; }},
      {"range_rate_accuracy", [](SensorParams& p) { p.range_rate_accuracy = -1; }},
      {"off_boresight", [](SensorParams& p) { Profile(p, {0, 1}, {1, 2}, {1}); }},
      {"off_boresight", [](SensorParams& p) { Profile(p, {0.5, 0.5}, {1, 2}, {1, 2}); }},
      {"off_boresight", [](SensorParams& p) { Profile(p, {0, 4}, {1, 2}, {1, 2}); }},
      {"off_boresight_resolution", [](SensorParams& p) { Profile(p, {0, 1}, {0.5, 2}, {1, 2}); }},
      {"off_boresight_accuracy", [](SensorParams& p) { Profile(p, {0, 1}, {1, 2}, {1, 1e9}); }},
      {"reference_range", [](SensorParams& p) { p.reference_range = 0.0; }},
      {"reference_rcs_dbsm", [](SensorParams& p) { p.reference_rcs_dbsm = INFINITY; }},
      {"reference_pd", [](SensorParams& p) { p.reference_pd = 1.0; }},
      {"reference_pd", [](SensorParams& p) { p.reference_pd = 1e-7; }},
      {"false_alarm_rate", [](SensorParams& p) { p.false_alarm_rate = 0.0; }},
      {"false_alarm_rate", [](SensorParams& p) { p.false_alarm_rate = 0.7; }},
      {"update_period", [](SensorParams& p) { p.update_period = 0.0; }},
  }));
  const SensorParams base = GENERATE(DefaultShortRangeRadar(), DefaultLongRangeRadar());
  std::string error;
  REQUIRE(base.IsValid(&error));
  SensorParams bad = base;
  mutate(bad);
  error.clear();
  CHECK_FALSE(bad.IsValid(&error));
  // The message starts with the field name (an element of a list: with its index) and its value.
  INFO(error);
  CHECK((error.rfind(field + " = ", 0) == 0 || error.rfind(field + "[", 0) == 0));
  CHECK(error.find(": expected ") != std::string::npos);
  CHECK_FALSE(bad.IsValid(nullptr));
  // The model refuses it too, naming sensor and field.
  std::vector<SensorParams> rig = DefaultRig(4.5, 1.8);
  rig.push_back(bad);
  try {
    RadarModel model(rig, ModelOptions{}, 1);
    FAIL("RadarModel accepted an invalid sensor");
  } catch (const std::invalid_argument& e) {
    CHECK_THAT(e.what(), Catch::Contains("): " + field) && Catch::Contains("sensor 5"));
  }
}

TEST_CASE("SensorsDue fires each sensor once per elapsed update period", "[radar][timing]") {
  const double period = GENERATE(0.05, 0.072, 0.1, 0.25);
  const double dt = GENERATE(0.05, 0.1);
  SensorParams p = DefaultShortRangeRadar();
  p.update_period = period;
  const RadarModel model({p}, ModelOptions{}, 3);
  const int steps = 400;
  int fired = 0;
  for (int k = 0; k < steps; ++k) {
    const double t = k * dt;
    const std::vector<int> due = model.SensorsDue(t, dt);
    REQUIRE(due.size() <= 1);
    if (k == 0) CHECK(due.size() == 1);  // every sensor fires at time 0
    fired += static_cast<int>(due.size());
  }
  // Multiples of the period in [0, t_last] (one per step at most when the period is shorter).
  const double t_last = (steps - 1) * dt;
  const int expected =
      period >= dt ? static_cast<int>(std::floor(t_last / period + 1e-9)) + 1 : steps;
  CHECK(fired == expected);
}
