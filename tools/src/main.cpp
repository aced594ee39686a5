// dualgrid: SUMO traffic -> radar detections -> dynamic occupancy grid, scored against truth.
#include <unistd.h>

#include <iostream>
#include <thread>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "dualgrid/sim/sumo_simulation.hpp"

namespace {

using namespace dualgrid::tools;

void AddRunOptions(CLI::App* cmd, RunOptions* o, const std::string& out_help) {
  cmd->add_option("scenario", o->scenario, "Scenario file (e.g. scenarios/highway.yaml)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out,-o", o->out, out_help)->required();
  cmd->add_option("--seed", o->seed, "Override the scenario's random seed");
  cmd->add_option("--duration", o->duration, "Override the scenario's duration [s]");
  cmd->add_option("--network-dir", o->network_dir,
                  "Folder of the generated .net.xml files (default: the build's networks/)");
  cmd->add_flag("--quiet,-q", o->quiet, "No progress or summary output");
}

void AddFilterOptions(CLI::App* cmd, FilterRunOptions* o) {
  cmd->add_option("--modes", o->modes, "Weight modes to run side by side")
      ->delimiter(',')
      ->check(CLI::IsMember({"position", "velocity", "dual"}));
  cmd->add_option("--snapshots", o->snapshots, "Times [s] of the grid pictures (comma-separated)")
      ->delimiter(',');
  cmd->add_flag("!--no-figures", o->figures, "Skip the pictures");
  cmd->add_flag("--write-detections", o->write_detections, "Also write detections.csv");
  cmd->add_option("--threads", o->threads, "OpenMP threads (default: all cores)")
      ->check(CLI::NonNegativeNumber);
}

std::string SelfPath(const char* argv0) {
  char buf[4096];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  return n > 0 ? std::string(buf, n) : std::string(argv0);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "dualgrid: radar-only dynamic occupancy grid with dual particle weights, "
      "co-simulated with SUMO.\nScenarios are YAML files (see scenarios/ and "
      "docs/scenarios.md)."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "dualgrid 0.1.0");
  const auto network_dir = dualgrid::sim::DefaultNetworkDir();

  RunOptions sim_options;
  sim_options.network_dir = network_dir;
  auto* sim = app.add_subcommand(
      "sim", "Run SUMO and the radar model; write ground truth and detections (CSV)");
  AddRunOptions(sim, &sim_options, "Output folder");

  SnapshotOptions snap;
  snap.run.network_dir = network_dir;
  auto* snapshot = app.add_subcommand(
      "snapshot",
      "Bird's-eye picture (PNG) of a scenario at one time: road, vehicles, radar "
      "fields of view, detections with radial-velocity arrows");
  AddRunOptions(snapshot, &snap.run, "PNG file to write");
  snapshot->add_option("--time,-t", snap.time, "Scenario time [s]")->required();
  snapshot->add_option("--behind", snap.behind, "View behind the ego [m]");
  snapshot->add_option("--ahead", snap.ahead, "View ahead of the ego [m]");
  snapshot->add_option("--half-width", snap.half_width, "View to each side of the ego [m]");

  FilterRunOptions run_options;
  run_options.run.network_dir = network_dir;
  auto* run = app.add_subcommand(
      "run",
      "Run SUMO, the radar and the grid filters (one per weight mode, same detections) "
      "and score them against the ground truth");
  AddRunOptions(run, &run_options.run, "Run folder (metrics, tables, figures, config)");
  AddFilterOptions(run, &run_options);

  ExperimentOptions exp;
  exp.run.run.network_dir = network_dir;
  auto* experiment =
      app.add_subcommand("experiment",
                         "`run` over several seeds (separate processes) and aggregate the tables "
                         "with 95 % confidence intervals");
  AddRunOptions(experiment, &exp.run.run, "Experiment folder");
  AddFilterOptions(experiment, &exp.run);
  experiment->add_option("--seeds", exp.seeds, "Number of seeds")->check(CLI::PositiveNumber);
  experiment->add_option("--first-seed", exp.first_seed, "First seed");
  experiment->add_option("--jobs,-j", exp.jobs, "Parallel runs (default: number of cores)");

  TangentialOptions tan;
  auto* tangential =
      app.add_subcommand("tangential",
                         "Write a tangential-motion stress scenario (traffic crossing ahead of the "
                         "ego, or driving alongside it), to run with `dualgrid run`");
  tangential->add_option("--kind", tan.kind, "crossing or parallel")
      ->check(CLI::IsMember({"crossing", "parallel"}));
  tangential->add_option("--count", tan.count, "Number of stress vehicles");
  tangential->add_option("--ego-speed", tan.ego_speed, "Ego speed [m/s]");
  tangential->add_option("--speed", tan.speed,
                         "Crossing speed [m/s]; parallel: speed over the ego's [m/s]");
  tangential->add_option("--first-distance", tan.first_distance,
                         "crossing: distance ahead of the ego of the first crossing [m]");
  tangential->add_option("--spacing", tan.spacing, "Distance between stress vehicles [m]");
  tangential->add_option("--seed", tan.seed, "Scenario seed");
  tangential->add_option("--out,-o", tan.out, "Scenario file to write")->required();
  tangential->add_flag("--quiet,-q", tan.quiet, "No summary");

  CLI11_PARSE(app, argc, argv);
  try {
    if (sim->parsed()) return RunSim(sim_options);
    if (tangential->parsed()) {
      // Parallel defaults: nearly the ego's speed, and spacing that leaves SUMO's insertion gap.
      if (tan.kind == "parallel" && tangential->count("--speed") == 0) tan.speed = 0.3;
      if (tan.kind == "parallel" && tangential->count("--spacing") == 0) tan.spacing = 40.0;
      return RunTangential(tan);
    }
    if (snapshot->parsed()) return RunSnapshot(snap);
    if (run->parsed()) return RunFilters(run_options);
    if (experiment->parsed()) {
      exp.executable = SelfPath(argv[0]);
      // Parallel runs share the cores: one OpenMP thread each unless told otherwise.
      const int jobs =
          exp.jobs > 0 ? exp.jobs : static_cast<int>(std::thread::hardware_concurrency());
      if (exp.run.threads == 0 && jobs > 1) exp.run.threads = 1;
      return RunExperiment(exp);
    }
  } catch (const std::exception& e) {
    std::cerr << "dualgrid: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
