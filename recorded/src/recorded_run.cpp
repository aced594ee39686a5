#include "dualgrid/recorded/recorded_run.hpp"

#include <stdexcept>

#include "dualgrid/recorded/radarscenes.hpp"
#include "dualgrid/recorded/run_folder.hpp"

namespace dualgrid::recorded {

RecordedInput ReadRecordedInput(const std::filesystem::path& input,
                                const std::optional<std::filesystem::path>& sensors) {
  RecordedInput r;
  r.radarscenes = std::filesystem::exists(input / "scenes.json");
  if (!r.radarscenes && !std::filesystem::exists(input / "scans.csv") &&
      !std::filesystem::exists(input / "summary.json"))
    throw std::invalid_argument(input.string() +
                                ": neither a RadarScenes sequence folder (scenes.json) nor a "
                                "dualgrid run folder (scans.csv)");
  if (sensors && !r.radarscenes)
    throw std::invalid_argument("--sensors: only for a RadarScenes sequence");
  r.sequence = r.radarscenes ? ReadRadarScenes(input, sensors) : ReadRunFolder(input);
  return r;
}

}  // namespace dualgrid::recorded
