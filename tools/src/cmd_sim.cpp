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
#include "dualgrid/sim/sumo_simulation.hpp"
#include "progress.hpp"
#include "signals.hpp"

namespace dualgrid::tools {

namespace {

// What summary.json counts over the run: detections, clutter and ghosts, and every vehicle seen
// with its first and last time and its closest approach to the ego.
struct SimTally {
  struct Seen {
    std::string type;
    double first = 0, last = 0, min_distance = 1e9;
  };
  std::map<std::string, Seen> seen;
  std::size_t detections = 0, clutter = 0, ghosts = 0;
  int steps = 0;

  void Add(const cosim::Pipeline& pipeline) {
    const sim::Frame& f = pipeline.frame();
    detections += pipeline.detections().size();
    for (const auto& d : pipeline.detections()) {
      clutter += d.is_clutter ? 1 : 0;
      ghosts += d.path != radar::Path::kDirect ? 1 : 0;
    }
    for (const auto& v : f.vehicles) {
      auto [it, inserted] = seen.try_emplace(v.id, Seen{v.type, f.time, f.time, 1e9});
      it->second.last = f.time;
      it->second.min_distance =
          std::min(it->second.min_distance, (v.box.center - f.ego.box.center).norm());
    }
    ++steps;
  }
};

// The per-step files of `sim`: ground truth, and the detections (with scans.csv when exact).
struct SimFiles {
  SimFiles(const SimOptions& o, bool multipath)
      : truth(o.run.out / "ground_truth.csv"), exact(ExactDetections(o.detections)) {
    if (const auto path = DetectionPath(o.run.out, o.detections))
      detections = std::make_unique<DetectionWriter>(*path, multipath, exact);
    if (exact) scans = std::make_unique<ScanWriter>(o.run.out / "scans.csv");
  }
  void Write(const cosim::Pipeline& pipeline) {
    truth.Write(pipeline.frame());
    if (detections) detections->Write(pipeline);
    if (scans) scans->Write(pipeline);
  }
  void Close() {
    truth.Close();
    if (detections) detections->Close();
    if (scans) scans->Close();
  }
  GroundTruthWriter truth;
  bool exact;
  std::unique_ptr<DetectionWriter> detections;
  std::unique_ptr<ScanWriter> scans;
};

nlohmann::json SimSummary(const cosim::CoSimulation& cosim, const scenario::ScenarioConfig& config,
                          const SimTally& t, double wall, std::string* status) {
  const sim::ScenarioSpec& spec = config.sim;
  nlohmann::json summary = EndRecord(cosim, StopSignal(), status);
  summary["status"] = *status;
  summary["scenario"] = spec.name;
  summary["seed"] = spec.seed;
  summary["steps"] = t.steps;
  summary["simulated_s"] = t.steps * spec.step_length;
  summary["wall_s"] = wall;
  summary["detections"] = t.detections;
  summary["clutter_detections"] = t.clutter;
  if (config.radar.options.multipath.enabled) summary["ghost_detections"] = t.ghosts;
  summary["sensors"] = nlohmann::json::array();
  for (const auto& sensor : config.radar.sensors) summary["sensors"].push_back(sensor.name);
  for (const auto& [id, s] : t.seen) {
    summary["vehicles"][id] = {{"type", s.type},
                               {"first_s", s.first},
                               {"last_s", s.last},
                               {"min_distance_to_ego_m", s.min_distance}};
  }
  summary["requested_s"] = spec.duration;
  return summary;
}

}  // namespace

int RunSim(const SimOptions& sim_options) {
  const RunOptions& options = sim_options.run;
  scenario::ScenarioConfig config = LoadConfig(options);
  DetectionPath(options.out, sim_options.detections);  // a bad --detections: before SUMO
  const sim::ScenarioSpec& spec = config.sim;
  cosim::CoSimulation cosim(config, {.modes = {}});        // SUMO and the radar, no filter
  sim::ResolveNetwork(spec.network, options.network_dir);  // before the folder is made
  outputs::InputSet inputs;
  inputs.AddScenario(config, options.network_dir);
  outputs::CheckOutputApart(options.out, inputs);
  PrepareOutputFolder(options.out, {.force = options.force});
  CopyScenario(config, options.out);

  const auto wall_start = std::chrono::steady_clock::now();
  cosim.Start(options.network_dir, options.out);
  const cosim::Pipeline& pipeline = cosim.pipeline();
  PrintAutoEgoNote(pipeline, options.quiet);
  SimFiles files(sim_options, config.radar.options.multipath.enabled);
  WriteObstacles(spec, options.out / "obstacles.csv");
  SimTally tally;
  Progress progress("sim " + spec.name, spec.StepCount(), !options.quiet);
  while (!StopSignal() && cosim.Step()) {
    files.Write(pipeline);
    tally.Add(pipeline);
    const sim::Frame& f = pipeline.frame();
    progress.Update(tally.steps, "t=" + FormatFixed(f.time, 1) + " s, " +
                                     std::to_string(f.vehicles.size()) + " vehicles");
  }
  cosim.Finish();
  progress.Finish();
  files.Close();
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();

  std::string status;
  nlohmann::json summary = SimSummary(cosim, config, tally, wall, &status);
  summary["digests"] = OutputDigests(options.out);
  SealOutputFolder(options.out);
  // Written last: a folder without summary.json did not finish.
  WriteTextFile(options.out / "summary.json", summary.dump(2) + "\n");
  const int steps = tally.steps;
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
              << FormatFixed(wall, 1) << " s), " << tally.seen.size() << " other vehicles, "
              << tally.detections << " radar detections; output in " << options.out.string()
              << "\n";
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
