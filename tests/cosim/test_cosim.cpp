// dualgrid::cosim linked directly: the step's observers see every step in order, get the cell
// velocities exactly when one asks, errors surface where documented, SUMO can be run again in
// the same process, and the metrics do not depend on the thread count.
#include <omp.h>
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "dualgrid/cosim/cosimulation.hpp"

using namespace dualgrid;

namespace {

scenario::ScenarioConfig Highway(double duration) {
  auto config = scenario::LoadScenario("scenarios/highway.yaml");
  config.sim.duration = duration;
  return config;
}

std::filesystem::path WorkDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("dualgrid_test_cosim_" + name);
  std::filesystem::create_directories(dir);
  return dir;
}

// Records what it was shown; asks for velocities every `every`-th step.
struct Recorder : cosim::StepObserver {
  int every = 0;
  std::vector<int> steps;
  std::vector<double> times;
  int with_velocity_steps = 0, velocity_mismatches = 0, detections = 0;
  bool WantsVelocities(int step, double) override { return every > 0 && step % every == 0; }
  void OnStep(const cosim::StepView& v) override {
    steps.push_back(v.step);
    times.push_back(v.frame.time);
    detections += static_cast<int>(v.pipeline.detections().size());
    const bool asked = every > 0 && v.step % every == 0;
    with_velocity_steps += v.with_velocities ? 1 : 0;
    for (const auto& s : v.snapshots)
      if (s.mean_vx.empty() == asked || s.mean_vx.size() != (asked ? s.free.size() : 0u))
        ++velocity_mismatches;
  }
};

struct Thrower : cosim::StepObserver {
  int at = 0;
  void OnStep(const cosim::StepView& v) override {
    if (v.step == at) throw std::runtime_error("observer failed");
  }
};

std::vector<eval::ScenarioMetrics> RunHighway(int threads, const std::string& work,
                                              Recorder* recorder) {
  cosim::CoSimulation cs(Highway(6.0), {.threads = threads});
  cs.Start(sim::DefaultNetworkDir(), WorkDir(work));
  cs.AddObserver(recorder);
  while (cs.Step()) {
  }
  CHECK(cs.finished());
  CHECK(cs.steps() == cs.config().sim.StepCount());
  CHECK(cs.total_detections() == static_cast<std::size_t>(recorder->detections));
  return cs.Metrics();
}

}  // namespace

TEST_CASE("CoSimulation: observers, velocities on demand, determinism over threads",
          "[cosim][sumo]") {
  Recorder one, two;
  one.every = 7;
  two.every = 0;
  const auto m1 = RunHighway(1, "t1", &one);
  // A second SUMO in the same process, after the first has ended (the Python module relies on it).
  const auto m2 = RunHighway(2, "t2", &two);

  const double dt = Highway(6.0).sim.step_length;
  const int n = Highway(6.0).sim.StepCount();
  REQUIRE(n == static_cast<int>(std::lround(6.0 / dt)));
  REQUIRE(one.steps.size() == static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < one.steps.size(); ++i) {
    CHECK(one.steps[i] == static_cast<int>(i));
    CHECK(one.times[i] == Approx(dt * (i + 1)));
  }
  CHECK(one.with_velocity_steps == (n - 1) / 7 + 1);  // steps 0, 7, 14, ...
  CHECK(two.with_velocity_steps == 0);
  CHECK(one.velocity_mismatches == 0);
  CHECK(two.velocity_mismatches == 0);

  // The same detections and the same metrics, whatever the thread count and velocity requests.
  CHECK(one.detections == two.detections);
  REQUIRE(m1.size() == 3u);
  REQUIRE(m2.size() == 3u);
  // Every field, per object too, as written to metrics.json.
  for (std::size_t m = 0; m < 3; ++m) CHECK(nlohmann::json(m1[m]) == nlohmann::json(m2[m]));
  // The run saw and tracked its vehicles: the comparison is not vacuous.
  CHECK(m1[2].objects_scored > 0);
  CHECK(m1[2].matches > 0);
  CHECK(m1[2].cells.has_value());
}

TEST_CASE("CoSimulation: errors before SUMO starts, and an observer's error", "[cosim][sumo]") {
  SECTION("memory beyond the machine is refused before anything is allocated or started") {
    auto config = Highway(1.0);
    config.filter.num_particles = 2'000'000'000;
    CHECK_THROWS_AS(cosim::CoSimulation(config), std::invalid_argument);
    CHECK_THROWS_WITH(cosim::CoSimulation(config), Catch::Contains("filter.num_particles"));
  }
  SECTION("an invalid sensor is named") {
    auto config = Highway(1.0);
    config.radar.sensors.front().fov = -1.0;
    CHECK_THROWS_WITH(cosim::CoSimulation(config),
                      Catch::Contains(config.radar.sensors.front().name));
  }
  SECTION("stepping before Start is misuse") {
    cosim::CoSimulation cs(Highway(1.0), {.modes = {}});
    CHECK_THROWS_AS(cs.Step(), std::logic_error);
  }
  SECTION("a missing network is bad input") {
    cosim::CoSimulation cs(Highway(1.0), {.modes = {}});
    CHECK_THROWS_AS(cs.Start(WorkDir("nonet") / "none", WorkDir("nonet")), std::invalid_argument);
  }
  SECTION("an observer's exception leaves Step() after the step was done") {
    cosim::CoSimulation cs(Highway(1.0), {.modes = {filter::WeightMode::kDual}});
    cs.Start(sim::DefaultNetworkDir(), WorkDir("throw"));
    Thrower t;
    t.at = 2;
    cs.AddObserver(&t);
    CHECK(cs.Step());
    CHECK(cs.Step());
    CHECK_THROWS_WITH(cs.Step(), "observer failed");
    CHECK(cs.steps() == 3);
  }
}

TEST_CASE("CoSimulation without modes: SUMO and the radar only", "[cosim][sumo]") {
  cosim::CoSimulation cs(Highway(2.0), {.modes = {}});
  cs.Start(sim::DefaultNetworkDir(), WorkDir("nomodes"));
  Recorder r;
  cs.AddObserver(&r);
  while (cs.Step()) {
  }
  CHECK(static_cast<int>(r.steps.size()) == cs.config().sim.StepCount());
  CHECK(r.detections > 0);
  CHECK(cs.Metrics().empty());
  CHECK(cs.pipeline().has_radar());
  CHECK(cs.pipeline().radar().sensors().size() == cs.config().radar.sensors.size());
}
