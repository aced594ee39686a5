#include "dualgrid/recorded/recorded_run.hpp"

#include <stdexcept>

#include "dualgrid/core/input_file.hpp"

#include "dualgrid/recorded/radarscenes.hpp"
#include "dualgrid/recorded/run_folder.hpp"

namespace dualgrid::recorded {

RecordedInput ReadRecordedInput(const std::filesystem::path& input,
                                const std::optional<std::filesystem::path>& sensors,
                                const std::optional<NuScenesOptions>& nuscenes) {
  RecordedInput r;
  if (nuscenes) {
    if (sensors) throw std::invalid_argument("--sensors: only for a RadarScenes sequence");
    r.kind = "nuscenes";
    r.nuscenes = ReadNuScenes(input, *nuscenes);
    r.sequence = std::move(r.nuscenes->sequence);
    r.nuscenes->sequence = {};
    r.scenario = r.nuscenes->scenario;
    return r;
  }
  // What the folder holds decides how it is read; a name present but unusable (a loop, a FIFO)
  // counts as present, so that its reader names the reason.
  CheckInputFolder(input, "recorded input folder");
  r.radarscenes = InputExists(input / "scenes.json");
  const bool run_folder = InputExists(input / "scans.csv") || InputExists(input / "summary.json");
  if (!r.radarscenes && !run_folder) {
    std::error_code ec;
    for (std::filesystem::directory_iterator it(input, ec), end; !ec && it != end; it.increment(ec))
      if (InputExists(it->path() / "scene.json"))
        throw std::invalid_argument(input.string() + ": a nuScenes root (" +
                                    it->path().filename().string() +
                                    "/scene.json): give --scene NAME_OR_TOKEN");
    throw std::invalid_argument(input.string() +
                                ": neither a RadarScenes sequence folder (scenes.json) nor a "
                                "dualgrid run folder (scans.csv)");
  }
  if (sensors && !r.radarscenes)
    throw std::invalid_argument("--sensors: only for a RadarScenes sequence");
  r.sequence = r.radarscenes ? ReadRadarScenes(input, sensors) : ReadRunFolder(input);
  if (r.radarscenes) {
    r.kind = "radarscenes";
    // An export's scenario travels in the dataset root (two folders up).
    std::filesystem::path dir = std::filesystem::absolute(input).lexically_normal();
    if (dir.filename().empty()) dir = dir.parent_path();  // a trailing '/'
    const std::filesystem::path travelled = dir.parent_path().parent_path() / kTravellingScenario;
    if (InputExists(travelled)) r.scenario = travelled;  // checked when it is read
  }
  return r;
}

}  // namespace dualgrid::recorded
