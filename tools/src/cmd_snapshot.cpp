// `dualgrid snapshot`: a bird's-eye picture of a scenario at one time.
#include <iostream>

#include "commands.hpp"
#include "figures.hpp"
#include "output.hpp"
#include "pipeline.hpp"

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
    throw std::invalid_argument("--time must be in [" + Fixed(config.sim.step_length, 2) + ", " +
                                Fixed(config.sim.duration, 2) + "] s (one step to the duration)");
  config.sim.duration = options.time;
  // SUMO's route file and log are working files of this command only: a temporary folder,
  // removed afterwards (kept, and named, only if SUMO fails, for its log).
  TempDir work("snapshot");
  Pipeline pipeline(config, run.network_dir, work.path(), {});
  while (pipeline.Step()) {
  }
  if (png.has_parent_path()) std::filesystem::create_directories(png.parent_path());
  RenderScene(pipeline, png, options.behind, options.ahead, options.half_width);
  if (!run.quiet)
    std::cout << "wrote " << png.string() << " (t = " << Fixed(pipeline.frame().time, 2) << " s, "
              << pipeline.detections().size() << " detections)\n";
  return 0;
}

}  // namespace dualgrid::tools
