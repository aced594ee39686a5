// SUMO's own input files, read as SUMO users write them (docs/scenarios.md, "Bring your own SUMO
// scenario"): a .sumocfg's inputs, and what route files define. Every file is parsed as XML once,
// streaming (xml_scan.hpp): comments and text are never mistaken for elements.
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace dualgrid::sim {

/// The inputs of a SUMO configuration file, paths made absolute relative to its folder (as SUMO
/// resolves them).
struct SumoConfigInputs {
  std::filesystem::path net_file;                       ///< <input><net-file>
  std::vector<std::filesystem::path> route_files;       ///< <input><route-files>, comma-separated
  std::vector<std::filesystem::path> additional_files;  ///< <input><additional-files>
  std::optional<double> step_length;                    ///< <time><step-length> [s]: not used
};

/// Reads `cfg`. Throws std::invalid_argument naming the file (and line) when it cannot be read,
/// is not XML, or names no net-file. Only the elements above are read; everything else in it is
/// left to SUMO's defaults or the scenario (docs/scenarios.md lists what is taken).
SumoConfigInputs ReadSumoConfig(const std::filesystem::path& cfg);

/// What SUMO route and additional files define, in file order (SUMO reads vehicles, flows and
/// vTypes from both).
struct RouteFileIndex {
  /// A vehicle SUMO will simulate under this id: a <vehicle> or a <trip>, or the k-th member of
  /// a flow, "FLOW.k".
  struct Vehicle {
    std::string id;
    double depart = 0.0;  ///< [s]; flows: their begin
    std::string file;
  };
  struct Flow {
    std::string id;
    /// Members SUMO will create when the flow says (number, or end with period / vehsPerHour);
    /// std::nullopt when it depends on chance or on the run (probability, no end).
    std::optional<long> members;
    double begin = 0.0;  ///< [s]
    std::string file;
  };
  std::vector<Vehicle> vehicles;  ///< <vehicle> and <trip>
  std::vector<Flow> flows;        ///< <flow>
  /// Every other id-bearing element by id -> its tag ("vType", "route", "person", ...), for
  /// naming what an id is when it is not a vehicle.
  std::map<std::string, std::string> others;
  /// Per file and kind, elements SUMO simulates or loads that the radar and the scoring do not see
  /// (persons and containers; polygons and POIs): "<file>: N <person> element(s) ...".
  std::vector<std::string> warnings;
  /// Ids of <vType> and <vTypeDistribution> elements.
  std::set<std::string> types;
};

/// Adds what `files` define to `index`, each file parsed once; `what` names their role in
/// messages ("SUMO route file", "SUMO additional file"). Throws std::invalid_argument naming a
/// file that cannot be read or is not well-formed XML.
void IndexSumoFiles(const std::vector<std::string>& files, const std::string& what,
                    RouteFileIndex* index);

/// IndexSumoFiles over `additional_files`, then `route_files` (SUMO's loading order).
RouteFileIndex IndexRouteFiles(const std::vector<std::string>& route_files,
                               const std::vector<std::string>& additional_files = {});

/// std::nullopt when SUMO will simulate a vehicle named `id` from these files (a vehicle, a
/// trip, or FLOW.k with k a member the flow creates); otherwise why not, in words that fit after
/// "'ID' ", e.g. "is a vType, not a vehicle", "is a flow: its vehicles are 'f.0', 'f.1', ...".
std::optional<std::string> VehicleIdProblem(const RouteFileIndex& index, const std::string& id);

/// Up to `n` ids that VehicleIdProblem accepts, in departure order, quoted and comma-separated
/// ("'a', 'f.0', 'f.1'"), for error messages; "none" when the files define no vehicle.
std::string ExampleVehicleIds(const RouteFileIndex& index, std::size_t n = 5);

}  // namespace dualgrid::sim
