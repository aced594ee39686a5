#include "dualgrid/recorded/recorded_run.hpp"

#include <stdexcept>

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
  r.radarscenes = std::filesystem::exists(input / "scenes.json");
  if (!r.radarscenes && !std::filesystem::exists(input / "scans.csv") &&
      std::filesystem::is_directory(input))
    for (const auto& e : std::filesystem::directory_iterator(input))
      if (std::filesystem::exists(e.path() / "scene.json"))
        throw std::invalid_argument(input.string() + ": a nuScenes root (" +
                                    e.path().filename().string() +
                                    "/scene.json): give --scene NAME_OR_TOKEN");
  if (!r.radarscenes && !std::filesystem::exists(input / "scans.csv") &&
      !std::filesystem::exists(input / "summary.json"))
    throw std::invalid_argument(input.string() +
                                ": neither a RadarScenes sequence folder (scenes.json) nor a "
                                "dualgrid run folder (scans.csv)");
  if (sensors && !r.radarscenes)
    throw std::invalid_argument("--sensors: only for a RadarScenes sequence");
  r.sequence = r.radarscenes ? ReadRadarScenes(input, sensors) : ReadRunFolder(input);
  if (r.radarscenes) {
    r.kind = "radarscenes";
    // An export's scenario travels in the dataset root (two folders up).
    std::filesystem::path dir = std::filesystem::absolute(input).lexically_normal();
    if (dir.filename().empty()) dir = dir.parent_path();  // a trailing '/'
    const std::filesystem::path travelled = dir.parent_path().parent_path() / kTravellingScenario;
    if (std::filesystem::is_regular_file(travelled)) r.scenario = travelled;
  }
  return r;
}

}  // namespace dualgrid::recorded
