// `dualgrid snapshot`: a bird's-eye picture of a scenario at one time.
#include <iostream>

#include "cli_options.hpp"
#include "commands.hpp"
#include "dualgrid/core/text.hpp"
#include "dualgrid/cosim/cosimulation.hpp"
#include "dualgrid/outputs/csv_writers.hpp"
#include "dualgrid/outputs/figures.hpp"
#include "dualgrid/outputs/output_file.hpp"
#include "dualgrid/outputs/run_folder.hpp"

namespace dualgrid::tools {

int RunSnapshot(const SnapshotOptions& options) {
  RunOptions run = options.run;
  const std::filesystem::path png = run.out;
  // The extension picks the format: a raster, or vectors for papers.
  if (png.extension() != ".png" && png.extension() != ".svg" && png.extension() != ".pdf")
    throw std::invalid_argument("--out: expected a file name ending in .png, .svg or .pdf, got '" +
                                png.string() + "'");
  if (std::filesystem::is_directory(png))
    throw std::invalid_argument("--out: '" + png.string() +
                                "' is a folder; give a .png, .svg or .pdf file name");
  scenario::ScenarioConfig config = LoadConfig(run);
  if (!(options.time >= config.sim.step_length && options.time <= config.sim.duration))
    throw std::invalid_argument("--time must be in [" + FormatFixed(config.sim.step_length, 2) +
                                ", " + FormatFixed(config.sim.duration, 2) +
                                "] s (one step to the duration)");
  config.sim.duration = options.time;
  // SUMO's route file and log are working files of this command only: a temporary folder,
  // removed afterwards (kept, and named, only if SUMO fails, for its log).
  TempDir work("snapshot");
  cosim::CoSimulation cosim(config, {.modes = {}});  // SUMO and the radar, no filter
  cosim.Start(run.network_dir, work.path());
  while (cosim.Step()) {
  }
  const cosim::Pipeline& pipeline = cosim.pipeline();
  if (!pipeline.has_radar())
    throw std::runtime_error("the ego never departed before t = " + FormatFixed(options.time, 2) +
                             " s: nothing to draw");
  if (png.has_parent_path()) std::filesystem::create_directories(png.parent_path());
  RenderScene(pipeline, png, options.behind, options.ahead, options.half_width,
              options.figure_captions);
  if (!run.quiet)
    std::cout << "wrote " << png.string() << " (t = " << FormatFixed(pipeline.frame().time, 2)
              << " s, " << pipeline.detections().size() << " detections)\n";
  return 0;
}

Command AddSnapshotCommand(CLI::App& app, const CliContext& ctx) {
  auto o = std::make_shared<SnapshotOptions>();
  o->run.network_dir = ctx.network_dir;
  auto* cmd = app.add_subcommand(
      "snapshot",
      "Bird's-eye picture (PNG) of a scenario at one time: road, vehicles, radar "
      "fields of view, detections with radial-velocity arrows");
  AddRunOptions(cmd, &o->run, "PNG file to write (must end in .png)", true);
  cmd->add_option("--time,-t", o->time, "Scenario time [s]")
      ->required()
      ->check(Number(0.0, kMaxDuration, true));
  Opt(cmd, "--behind", &o->behind, "View behind the ego [m]")->check(Number(0.0, 2000.0, true));
  Opt(cmd, "--ahead", &o->ahead, "View ahead of the ego [m]")->check(Number(0.0, 2000.0, true));
  Opt(cmd, "--half-width", &o->half_width, "View to each side of the ego [m]")
      ->check(Number(0.0, 1000.0, true));
  AddCaptionOption(cmd, &o->figure_captions);
  return {cmd, [o] { return RunSnapshot(*o); }};
}

}  // namespace dualgrid::tools
