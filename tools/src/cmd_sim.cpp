// `dualgrid sim`: SUMO ground truth (and radar detections) per step, written as CSV.
#include <chrono>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>

#include <nlohmann/json.hpp>

#include "cli_options.hpp"
#include "commands.hpp"
#include "dualgrid/core/text.hpp"
#include "dualgrid/cosim/cosimulation.hpp"
#include "dualgrid/outputs/csv_writers.hpp"
#include "dualgrid/outputs/output_file.hpp"
#include "dualgrid/outputs/run_config.hpp"
#include "dualgrid/outputs/run_folder.hpp"
#include "dualgrid/scenario/loader.hpp"
#include "progress.hpp"
#include "signals.hpp"

namespace dualgrid::tools {

int RunSim(const SimOptions& sim_options) {
  const RunOptions& options = sim_options.run;
  scenario::ScenarioConfig config = LoadConfig(options);
  const auto detections_path = DetectionPath(options.out, sim_options.detections);
  const sim::ScenarioSpec& spec = config.sim;
  cosim::CoSimulation cosim(config, {.modes = {}});  // SUMO and the radar, no filter
  PrepareOutputFolder(options.out);
  CopyScenario(config, options.out);

  const auto wall_start = std::chrono::steady_clock::now();
  cosim.Start(options.network_dir, options.out);
  const cosim::Pipeline& pipeline = cosim.pipeline();
  if (const std::string note = AutoEgoNote(pipeline); !note.empty() && !options.quiet)
    std::cerr << "dualgrid: " << note << "\n";
  GroundTruthWriter truth(options.out / "ground_truth.csv");
  std::unique_ptr<DetectionWriter> detections;
  const bool multipath = config.radar.options.multipath.enabled;
  const bool exact = ExactDetections(sim_options.detections);
  if (detections_path)
    detections = std::make_unique<DetectionWriter>(*detections_path, multipath, exact);
  std::unique_ptr<ScanWriter> scans;
  if (exact) scans = std::make_unique<ScanWriter>(options.out / "scans.csv");
  WriteObstacles(spec, options.out / "obstacles.csv");

  struct Seen {
    std::string type;
    double first = 0, last = 0, min_distance = 1e9;
  };
  std::map<std::string, Seen> seen;
  Progress progress("sim " + spec.name, spec.StepCount(), !options.quiet);
  int steps = 0;
  std::size_t detection_count = 0, clutter_count = 0, ghost_count = 0;
  while (!StopSignal() && cosim.Step()) {
    const sim::Frame& f = pipeline.frame();
    truth.Write(f);
    if (detections) detections->Write(pipeline);
    if (scans) scans->Write(pipeline);
    detection_count += pipeline.detections().size();
    for (const auto& d : pipeline.detections()) {
      clutter_count += d.is_clutter ? 1 : 0;
      ghost_count += d.path != radar::Path::kDirect ? 1 : 0;
    }
    for (const auto& v : f.vehicles) {
      auto [it, inserted] = seen.try_emplace(v.id, Seen{v.type, f.time, f.time, 1e9});
      it->second.last = f.time;
      it->second.min_distance =
          std::min(it->second.min_distance, (v.box.center - f.ego.box.center).norm());
    }
    ++steps;
    progress.Update(steps, "t=" + FormatFixed(f.time, 1) + " s, " +
                               std::to_string(f.vehicles.size()) + " vehicles");
  }
  cosim.Finish();
  progress.Finish();
  truth.Close();
  if (detections) detections->Close();
  if (scans) scans->Close();
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();

  std::string status;
  nlohmann::json summary = EndRecord(cosim, StopSignal(), &status);
  summary["status"] = status;
  summary["scenario"] = spec.name;
  summary["seed"] = spec.seed;
  summary["steps"] = steps;
  summary["simulated_s"] = steps * spec.step_length;
  summary["wall_s"] = wall;
  summary["detections"] = detection_count;
  summary["clutter_detections"] = clutter_count;
  if (multipath) summary["ghost_detections"] = ghost_count;
  summary["sensors"] = nlohmann::json::array();
  for (const auto& sensor : config.radar.sensors) summary["sensors"].push_back(sensor.name);
  for (const auto& [id, s] : seen) {
    summary["vehicles"][id] = {{"type", s.type},
                               {"first_s", s.first},
                               {"last_s", s.last},
                               {"min_distance_to_ego_m", s.min_distance}};
  }
  summary["requested_s"] = spec.duration;
  summary["digests"] = OutputDigests(options.out);
  // Written last: a folder without summary.json did not finish.
  WriteTextFile(options.out / "summary.json", summary.dump(2) + "\n");
  if (StopSignal()) {
    std::cerr << "dualgrid: stopped by signal " << StopSignal()
              << " at t = " << FormatFixed(steps * spec.step_length, 2)
              << " s; the simulated part is in " << options.out.string() << "\n";
    return StopExitCode();
  }
  if (!status.empty()) std::cerr << "dualgrid: " << status << "\n";
  if (!options.quiet) {
    std::cout << spec.name << ": " << steps << " steps ("
              << FormatFixed(steps * spec.step_length, 1) << " s simulated in "
              << FormatFixed(wall, 1) << " s), " << seen.size() << " other vehicles, "
              << detection_count << " radar detections; output in " << options.out.string() << "\n";
  }
  return 0;
}

Command AddSimCommand(CLI::App& app, const CliContext& ctx) {
  auto o = std::make_shared<SimOptions>();
  o->run.network_dir = ctx.network_dir;
  auto* cmd = app.add_subcommand(
      "sim", "Run SUMO and the radar model; write ground truth and detections (CSV)");
  AddRunOptions(cmd, &o->run, "Output folder", true);
  Opt(cmd, "--detections", &o->detections,
      "Write the radar detections: none, csv, csv.gz (gzip, about 3.5x smaller), or exact (17 "
      "digits and scans.csv: the input of `dualgrid filter` and `dualgrid export`)")
      ->check(DetectionFormat());
  return {cmd, [o] { return RunSim(*o); }};
}

}  // namespace dualgrid::tools
