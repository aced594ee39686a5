#include "cli_options.hpp"

#include "dualgrid/outputs/run_config.hpp"
#include "dualgrid/sim/scenario.hpp"

namespace dualgrid::tools {

scenario::ScenarioConfig LoadConfig(const RunOptions& o) {
  return outputs::LoadRunConfig(o.scenario, o.sets, o.seed, o.duration, o.begin);
}

outputs::RunFolderOptions FilterRunOptions::FolderOptions() const {
  outputs::RunFolderOptions f = folder;
  f.out = run.out;
  f.force = run.force;
  f.network_dir = run.network_dir;
  f.quiet = run.quiet;
  f.output_thread = threads != 1;  // one thread asked for: one core, outputs in line
  return f;
}

void AddRunOptions(CLI::App* cmd, RunOptions* o, const std::string& out_help, bool with_seed) {
  cmd->add_option("scenario", o->scenario, "Scenario file (e.g. scenarios/highway.yaml)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out,-o", o->out, out_help)->required()->check(NonEmptyPath());
  if (with_seed)
    cmd->add_option("--seed", o->seed, "Random seed (default: the scenario's `seed`)")
        ->check(WholeNumber(0, static_cast<long long>(kMaxSeed)));
  cmd->add_option("--duration", o->duration,
                  "Simulated time [s] (default: the scenario's `duration`)")
      ->check(Number(0.0, kMaxDuration, true));
  cmd->add_option("--begin", o->begin,
                  "SUMO time [s] at which the run begins (default: the scenario's `begin`, else "
                  "its sumo_config's <begin>, else 0); --duration counts from it")
      ->check(Number(0.0, sim::kMaxBegin, false));
  Opt(cmd, "--network-dir", &o->network_dir,
      "Folder of the built networks named in scenarios (`network: highway`)")
      ->check(CLI::ExistingDirectory);
  cmd->add_flag("--quiet,-q", o->quiet, "No progress or summary output");
  AddForceFlag(cmd, &o->force);
  cmd->add_option("--set", o->sets,
                  "Override a scenario key, KEY=VALUE (repeatable): e.g. --set filter.preset=paper "
                  "--set filter.num_particles=3000; a number in KEY indexes a list "
                  "(traffic.vehicles.0.speed=20). Validated like the file")
      ->check(OverrideSpec());
}

void AddForceFlag(CLI::App* cmd, bool* force) {
  cmd->add_flag("--force", *force,
                "--out may hold an earlier dualgrid output: remove its own files (never others) "
                "and write anew (without it, a folder that is not empty is refused)");
}

void AddCaptionOption(CLI::App* cmd, bool* captions) {
  cmd->add_option_function<std::string>(
         "--figure-captions", [captions](const std::string& v) { *captions = v == "on"; },
         "Captions under the figures: on (default) or off (for a paper that sets its own)")
      ->check(CLI::IsMember({"on", "off"}));
}

CLI::Validator DetectionFormat() { return CLI::IsMember({"none", "csv", "csv.gz", "exact"}); }

void AddFilterOptions(CLI::App* cmd, FilterRunOptions* o, bool* no_figures) {
  cmd->add_option("--modes", o->modes,
                  "Weight modes to run side by side, comma-separated (default: all three)")
      ->delimiter(',')
      ->check(CLI::IsMember({"position", "velocity", "dual"}));
  cmd->add_option("--snapshots", o->folder.snapshots,
                  "Times [s] of the grid pictures, comma-separated (default: the scenario's "
                  "`evaluation.snapshot_times`, else 1/4, 1/2, 3/4 of the run)")
      ->delimiter(',')
      ->check(Number(0.0, kMaxDuration, true));
  cmd->add_flag("--no-figures", *no_figures, "Skip the pictures (metrics and tables only)");
  cmd->add_option("--figure-formats", o->folder.figure_formats,
                  "Formats of every figure, comma-separated: png (raster), svg, pdf (vectors) "
                  "(default: all three)")
      ->delimiter(',')
      ->check(CLI::IsMember({"png", "svg", "pdf"}));
  AddCaptionOption(cmd, &o->folder.figure_captions);
  cmd->add_flag_callback(
      "--write-detections", [o] { o->folder.detections = "csv"; }, "Same as --detections csv");
  Opt(cmd, "--detections", &o->folder.detections,
      "Write the radar detections: none, csv, csv.gz (gzip, about 3.5x smaller), or exact (17 "
      "digits and scans.csv: the input of `dualgrid filter` and `dualgrid export`)")
      ->check(DetectionFormat());
  cmd->add_flag("--write-particles", o->folder.write_particles,
                "Write every particle beside each grid picture (figures/particles_*.csv, several "
                "MB each)");
  cmd->add_flag("--check-invariants", o->folder.check_invariants,
                "Check the filters' invariants every step and sample the resident memory (soak "
                "tests; docs/reliability.md)");
  cmd->add_option("--threads", o->threads,
                  "OpenMP threads per run (default 0: all cores; at most " +
                      std::to_string(kMaxThreadsPerCore) + " per core)")
      ->check(WholeNumber(0, kMaxThreadsPerCore * Cores()));
}

}  // namespace dualgrid::tools
