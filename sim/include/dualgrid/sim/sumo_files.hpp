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

#include "dualgrid/sim/scenario.hpp"

namespace dualgrid::sim {

/// What SUMO took from a configuration file (its own reading: ReadSumoConfig), paths absolute.
struct SumoConfigInputs {
  std::filesystem::path net_file;                       ///< net-file
  std::vector<std::filesystem::path> route_files;       ///< route-files
  std::vector<std::filesystem::path> additional_files;  ///< additional-files
  std::optional<double> step_length;                    ///< step-length [s]: not used
  double begin = 0.0;                                   ///< begin [s, SUMO time]; SUMO's default 0
  std::optional<double> end;                            ///< end [s, SUMO time], when given
  std::optional<std::string> remote_port;  ///< remote-port (TraCI): never opened (libsumo)
};

/// Reads `cfg` as SUMO reads it: the file is checked first (a regular file, bounded, well-formed
/// XML: xml_scan.hpp), then `sumo -c CFG --save-configuration` (a child process, which exits
/// without simulating) writes SUMO's own reading of every option, synonyms and attribute forms
/// resolved, into a temporary folder that is removed. Throws std::invalid_argument naming the
/// file (and SUMO's first error line, or the option) when it cannot be read, SUMO refuses it,
/// it names no net-file or more than one (a list "a.net.xml,b.net.xml": SUMO would merge them),
/// or a time or step length is not a number; std::runtime_error when
/// `sumo` cannot be started.
SumoConfigInputs ReadSumoConfig(const std::filesystem::path& cfg);

/// What SUMO route and additional files define, in file order (SUMO reads vehicles, flows and
/// vTypes from both).
struct RouteFileIndex {
  /// A vehicle SUMO will simulate under this id: a <vehicle> or a <trip>, or the k-th member of
  /// a flow, "FLOW.k".
  struct Vehicle {
    std::string id;
    double depart = 0.0;  ///< [s, SUMO time] (0 when not a number: "triggered", ...)
    bool timed = false;   ///< `depart` is a number of seconds
    std::string file;
  };
  struct Flow {
    std::string id;
    /// Members SUMO will create when the flow says (number, or end with period / vehsPerHour);
    /// std::nullopt when it depends on chance or on the run (probability, no end).
    std::optional<long> members;
    double begin = 0.0;            ///< [s, SUMO time]
    std::optional<double> end;     ///< [s, SUMO time] when given
    std::optional<double> period;  ///< [s] between members (period, or 3600 / vehsPerHour)
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
/// file that cannot be read or is not well-formed XML, and "<file>:<line>: <vType id="x">
/// length="nan": expected in (0, 30] m" for a number of a <vType> (or <carFollowing-...>),
/// <vehicle>, <trip> or <flow> outside the ranges of vehicle_ranges.hpp, or an unknown vClass.
void IndexSumoFiles(const std::vector<std::string>& files, const std::string& what,
                    RouteFileIndex* index);

/// IndexSumoFiles over `additional_files`, then `route_files` (SUMO's loading order).
RouteFileIndex IndexRouteFiles(const std::vector<std::string>& route_files,
                               const std::vector<std::string>& additional_files = {});

/// std::nullopt when SUMO will simulate a vehicle named `id` from these files (a vehicle, a
/// trip, or FLOW.k with k a member the flow creates); otherwise why not, in words that fit after
/// "'ID' ", e.g. "is a vType, not a vehicle", "is a flow: its vehicles are 'f.0', 'f.1', ...".
std::optional<std::string> VehicleIdProblem(const RouteFileIndex& index, const std::string& id);

/// When SUMO departs the vehicle `id` of these files in a run that begins at `begin` [s, SUMO
/// time], as ScenarioSpec::ego_departure records it; std::nullopt when the files do not say (a
/// departure that is not a number, a flow without a period).
std::optional<FileDeparture> DepartureOf(const RouteFileIndex& index, const std::string& id);

/// Up to `n` ids that VehicleIdProblem accepts, in departure order, quoted and comma-separated
/// ("'a', 'f.0', 'f.1'"), for error messages; "none" when the files define no vehicle.
std::string ExampleVehicleIds(const RouteFileIndex& index, std::size_t n = 5);

}  // namespace dualgrid::sim
