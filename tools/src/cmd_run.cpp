// `dualgrid run`: one SUMO run, one radar stream, three filters side by side, scored per step.
#include <algorithm>
#include <iostream>

#include "cli_options.hpp"
#include "commands.hpp"
#include "dualgrid/core/text.hpp"
#include "dualgrid/cosim/cosimulation.hpp"
#include "dualgrid/outputs/run.hpp"
#include "progress.hpp"
#include "signals.hpp"

namespace dualgrid::tools {

std::vector<filter::WeightMode> ParseModes(const std::vector<std::string>& names) {
  std::vector<filter::WeightMode> modes;
  for (const std::string& n : names) {
    const auto m = filter::ParseWeightMode(n);
    if (!m)
      throw std::invalid_argument("unknown mode '" + n + "' (expected position, velocity, dual)");
    if (std::find(modes.begin(), modes.end(), *m) != modes.end())
      throw std::invalid_argument("mode '" + n + "' given twice");
    modes.push_back(*m);
  }
  if (modes.empty()) throw std::invalid_argument("--modes needs at least one mode");
  return modes;
}

int RunFilters(const FilterRunOptions& options) {
  const std::vector<filter::WeightMode> modes = ParseModes(options.modes);
  scenario::ScenarioConfig config = LoadConfig(options.run);
  const outputs::RunFolderOptions folder = options.FolderOptions();
  folder.Validate();
  outputs::SnapshotTimes(folder.snapshots, config);  // bad --snapshots: before SUMO
  // Validates (memory, sensors) before anything is written; SUMO starts below.
  cosim::CoSimulation cosim(config, {modes, options.threads});
  return WriteRunFolderAndReport(cosim, config, folder, nullptr);
}

int WriteRunFolderAndReport(cosim::CoSimulation& cosim, const scenario::ScenarioConfig& config,
                            const outputs::RunFolderOptions& folder,
                            const outputs::RecordedRun* recorded) {
  const outputs::RunFolderResult r =
      outputs::WriteRunFolder(cosim, config, folder, recorded, TerminalCallbacks(folder.quiet));
  if (!folder.quiet) std::cout << r.table_markdown << "\n";
  if (!r.status.empty())
    std::cerr << "dualgrid: " << r.status << "; results in " << folder.out.string() << "\n";
  if (r.stop) return StopExitCode();
  if (!folder.quiet)
    std::cout << config.sim.name << ": " << r.steps
              << (recorded ? " filter cycles in " : " steps in ") << FormatFixed(r.wall_s, 1)
              << " s; results in " << folder.out.string()
              << (r.warnings.empty() ? ""
                                     : " (" + std::to_string(r.warnings.size()) +
                                           " figure(s) not drawn, see the warnings above)")
              << "\n";
  return 0;
}

Command AddRunCommand(CLI::App& app, const CliContext& ctx) {
  auto o = std::make_shared<FilterRunOptions>();
  auto no_figures = std::make_shared<bool>(false);
  auto no_record = std::make_shared<bool>(false);
  o->run.network_dir = ctx.network_dir;
  auto* cmd = app.add_subcommand(
      "run",
      "Run SUMO, the radar and the grid filters (one per weight mode, same detections) "
      "and score them against the ground truth");
  AddRunOptions(cmd, &o->run, "Run folder (metrics, tables, figures, config)", true);
  AddFilterOptions(cmd, o.get(), no_figures.get());
  cmd->add_flag("--no-record", *no_record,
                "Do not record the replay frames (RUN_DIR/replay/; off anyway with --no-figures)");
  Opt(cmd, "--record-interval", &o->folder.record_interval,
      "Time between recorded replay frames [s], rounded to whole steps")
      ->check(Number(0.001, 60.0, true));
  Opt(cmd, "--record-particles", &o->folder.record_particles,
      "Particles recorded per mode and frame (an even subsample; 0: none)")
      ->check(WholeNumber(0, 1000000));
  cmd->add_flag("--video", o->folder.video,
                "Also write the replay video (replay.mp4 and a GIF preview; needs ffmpeg) as "
                "`dualgrid replay` would");
  cmd->add_flag(
      "--viewer", o->folder.viewer,
      "Also write the interactive viewer (replay.html) as `dualgrid replay --html` would");
  return {cmd, [o, no_figures, no_record] {
            o->folder.figures = !*no_figures;
            o->folder.record = o->folder.figures && !*no_record;
            if ((o->folder.video || o->folder.viewer) && !o->folder.record)
              throw std::invalid_argument(
                  "--video and --viewer need the recording: drop --no-record / --no-figures");
            return RunFilters(*o);
          }};
}

}  // namespace dualgrid::tools
