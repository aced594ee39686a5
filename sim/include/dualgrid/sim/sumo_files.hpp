// SUMO's own input files, read as SUMO users write them (docs/scenarios.md, "Bring your own SUMO
// scenario"): a .sumocfg's inputs, and what route files hold that the co-simulation cannot honour.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace dualgrid::sim {

/// The inputs of a SUMO configuration file, paths made absolute relative to its folder (as SUMO
/// resolves them).
struct SumoConfigInputs {
  std::filesystem::path net_file;                       ///< <input><net-file>
  std::vector<std::filesystem::path> route_files;       ///< <input><route-files>, comma-separated
  std::vector<std::filesystem::path> additional_files;  ///< <input><additional-files>: not used
  std::optional<double> step_length;                    ///< <time><step-length> [s]: not used
};

/// Reads `cfg`. Throws std::invalid_argument naming the file when it cannot be read or names no
/// net-file. Only the elements above are read; everything else in it is left to SUMO's defaults
/// or the scenario (docs/scenarios.md lists what is taken).
SumoConfigInputs ReadSumoConfig(const std::filesystem::path& cfg);

/// One line per kind of element of `route_files` that SUMO would simulate but the co-simulation
/// cannot honour (persons and containers: the radar model and the scoring know vehicles only),
/// naming the file, the element and how many there are. Throws std::invalid_argument naming a
/// file that cannot be read.
std::vector<std::string> RouteFileWarnings(const std::vector<std::string>& route_files);

/// True if a vehicle, trip or flow with this id appears in the route files (a text search for
/// id="ID": enough to catch a typo in ego.from_routes or evaluation.focus_object early).
bool RouteFilesDefine(const std::vector<std::string>& route_files, const std::string& id);

}  // namespace dualgrid::sim
