// Runs the highway scenario in SUMO and checks the ground truth it yields. One SUMO simulation
// per process (libsumo), so everything is checked from a single 50 s run.
#include <catch2/catch.hpp>

#include <map>
#include <set>

#include "dualgrid/scenario/loader.hpp"
#include "dualgrid/sim/sumo_simulation.hpp"

using namespace dualgrid;

TEST_CASE("Highway ground truth: velocities match position differences, lane changes included",
          "[sim][sumo]") {
  auto config = scenario::LoadScenario("scenarios/highway.yaml");
  config.sim.duration = 50.0;  // past the ramp merge (~33 s) and the cut-in (44-47 s)
  const auto work = std::filesystem::temp_directory_path() / "dualgrid_test_sumo";
  sim::SumoSimulation simulation(
      config.sim, sim::ResolveNetwork(config.sim.network, sim::DefaultNetworkDir()), work);

  CHECK_THROWS_AS(sim::SumoSimulation(config.sim, "x.net.xml", work), std::logic_error);

  std::map<std::string, sim::VehicleState> previous;
  const double dt = config.sim.step_length;
  int steps = 0, checked = 0, lane_change_steps = 0;
  double worst = 0.0;
  std::set<std::string> lane_changers;
  while (simulation.Step()) {
    const sim::Frame& f = simulation.frame();
    ++steps;
    REQUIRE(f.ego.id == "ego");
    CHECK(f.time == Approx(steps * dt));
    std::vector<const sim::VehicleState*> all{&f.ego};
    for (const auto& v : f.vehicles) all.push_back(&v);
    std::map<std::string, sim::VehicleState> current;
    for (const sim::VehicleState* v : all) {
      REQUIRE(v->box.length > 0);
      REQUIRE(v->box.width > 0);
      if (auto it = previous.find(v->id); it != previous.end()) {
        // SUMO integrates positions with the speed of the step (Euler), so the backward
        // difference of the centre equals the reported velocity up to the lane shape: a
        // polyline whose direction changes by up to ~0.6 deg per vertex on the ramp, i.e. an
        // error of |v| * 0.01 rad. Tolerance: 2 % of the speed plus 0.05 m/s.
        const Velocity fd = (v->box.center - it->second.box.center) / dt;
        const double err = (fd - v->velocity).norm();
        worst = std::max(worst, err);
        INFO(v->id << " at t=" << f.time << " fd=" << fd.transpose()
                   << " v=" << v->velocity.transpose() << " lane " << v->lane);
        CHECK(err <= 0.02 * v->velocity.norm() + 0.05);
        ++checked;
        // A lane change is continuous: the lateral speed is bounded (3.5 m over
        // lane_change_duration), never a one-step jump.
        if (std::abs(v->lateral_speed) > 0.1) {
          ++lane_change_steps;
          lane_changers.insert(v->id);
          CHECK(std::abs(v->lateral_speed) <= 3.5 / config.sim.lane_change_duration + 0.2);
        }
      }
      current[v->id] = *v;
    }
    previous = std::move(current);
  }
  CHECK(steps == config.sim.StepCount());
  // 1000 steps with 4-8 vehicles on the road at a time.
  CHECK(checked > 4000);
  // The merger changes lanes twice (ramp merge, cut-in); each takes 3 s = 60 steps.
  CHECK(lane_changers.count("merger") == 1);
  CHECK(lane_change_steps >= 100);
  WARN("worst velocity / finite-difference mismatch: " << worst << " m/s");
}
