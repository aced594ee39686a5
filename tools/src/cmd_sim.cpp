// `dualgrid sim`: SUMO ground truth (and radar detections) per step, written as CSV.
#include <chrono>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "dualgrid/scenario/loader.hpp"
#include "dualgrid/sim/sumo_simulation.hpp"
#include "output.hpp"
#include "progress.hpp"

namespace dualgrid::tools {

int RunSim(const RunOptions& options) {
  scenario::ScenarioConfig config = LoadConfig(options);
  const sim::ScenarioSpec& spec = config.sim;
  std::filesystem::create_directories(options.out);
  CopyScenario(config, options.out);

  const auto wall_start = std::chrono::steady_clock::now();
  sim::SumoSimulation simulation(spec, sim::ResolveNetwork(spec.network, options.network_dir),
                                 options.out);
  GroundTruthWriter truth(options.out / "ground_truth.csv");
  WriteObstacles(spec, options.out / "obstacles.csv");

  struct Seen {
    std::string type;
    double first = 0, last = 0, min_distance = 1e9;
  };
  std::map<std::string, Seen> seen;
  Progress progress("sim " + spec.name, spec.StepCount(), !options.quiet);
  int steps = 0;
  while (simulation.Step()) {
    const sim::Frame& f = simulation.frame();
    truth.Write(f);
    for (const auto& v : f.vehicles) {
      auto [it, inserted] = seen.try_emplace(v.id, Seen{v.type, f.time, f.time, 1e9});
      it->second.last = f.time;
      it->second.min_distance =
          std::min(it->second.min_distance, (v.box.center - f.ego.box.center).norm());
    }
    ++steps;
    progress.Update(
        steps, "t=" + Fixed(f.time, 1) + " s, " + std::to_string(f.vehicles.size()) + " vehicles");
  }
  progress.Finish();
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();

  nlohmann::json summary;
  summary["scenario"] = spec.name;
  summary["seed"] = spec.seed;
  summary["steps"] = steps;
  summary["simulated_s"] = steps * spec.step_length;
  summary["wall_s"] = wall;
  for (const auto& [id, s] : seen) {
    summary["vehicles"][id] = {{"type", s.type},
                               {"first_s", s.first},
                               {"last_s", s.last},
                               {"min_distance_to_ego_m", s.min_distance}};
  }
  std::ofstream(options.out / "summary.json") << summary.dump(2) << "\n";
  if (!options.quiet) {
    std::cout << spec.name << ": " << steps << " steps (" << Fixed(steps * spec.step_length, 1)
              << " s simulated in " << Fixed(wall, 1) << " s), " << seen.size()
              << " other vehicles; output in " << options.out.string() << "\n";
  }
  return 0;
}

}  // namespace dualgrid::tools
