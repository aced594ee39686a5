// dualgrid: SUMO traffic -> radar detections -> dynamic occupancy grid, scored against truth.
#include <iostream>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "dualgrid/sim/sumo_simulation.hpp"

namespace {

void AddRunOptions(CLI::App* cmd, dualgrid::tools::RunOptions* o, bool out_required = true) {
  cmd->add_option("scenario", o->scenario, "Scenario file (e.g. scenarios/highway.yaml)")
      ->required()
      ->check(CLI::ExistingFile);
  auto* out = cmd->add_option("--out,-o", o->out, "Output folder");
  if (out_required) out->required();
  cmd->add_option("--seed", o->seed, "Override the scenario's random seed");
  cmd->add_option("--duration", o->duration, "Override the scenario's duration [s]");
  cmd->add_option("--network-dir", o->network_dir,
                  "Folder of the generated .net.xml files (default: the build's networks/)");
  cmd->add_flag("--quiet,-q", o->quiet, "No progress or summary output");
}

}  // namespace

int main(int argc, char** argv) {
  using namespace dualgrid::tools;
  CLI::App app{
      "dualgrid: radar-only dynamic occupancy grid with dual particle weights, "
      "co-simulated with SUMO"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "dualgrid 0.1.0");

  RunOptions sim_options;
  sim_options.network_dir = dualgrid::sim::DefaultNetworkDir();
  auto* sim = app.add_subcommand("sim", "Run SUMO and write ground truth and radar detections");
  AddRunOptions(sim, &sim_options);

  CLI11_PARSE(app, argc, argv);
  try {
    if (sim->parsed()) return RunSim(sim_options);
  } catch (const std::exception& e) {
    std::cerr << "dualgrid: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
