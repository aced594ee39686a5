// The aspect-angle stress case (`dualgrid tangential --kind aspect`, docs/stress.md): targets whose
// motion makes a chosen aspect angle with a chosen sensor's line of sight. Pure: it returns the
// scenario and the plain-XML network it needs as text; the caller writes them and builds the
// network with netconvert.
#pragma once

#include <cstdint>
#include <string>

namespace dualgrid::scenario {

struct AspectCase {
  std::string sensor = "front";  ///< one of the default rig's sensors
  double angle_deg = 90.0;       ///< aspect angle theta in [0, 180] [deg]: 0 receding along the LOS
  double range = 20.0;           ///< sensor -> target centre at the reference time [m]
  double speed = 15.0;           ///< target speed over ground [m/s]
  double ego_speed = 0.0;        ///< [m/s], 0: a parked ego
  std::string target = "car";    ///< car, truck or cyclist
  int count = 1;                 ///< targets, one every `interval` seconds
  double interval = 6.0;         ///< [s] between the targets' reference times
  double grid_width = 25.0;      ///< filter.width_y [m] (the paper's 25 m)
  /// Widen the grid (to the smallest multiple of 5 m) when the targets would not be scored in
  /// `grid_width`, instead of refusing; the header says so.
  bool auto_grid_width = false;
  std::uint64_t seed = 1;
};

/// The texts of an aspect case: SUMO plain-XML nodes and edges, the scenario YAML (naming its
/// network `<stem>.net.xml`, to be built from `<stem>.nod.xml` and `<stem>.edg.xml` beside it),
/// and a one-line summary of the geometry.
struct AspectCaseFiles {
  std::string nodes, edges, scenario, summary;
};

/// Builds the case. Throws std::invalid_argument naming the option (--sensor, --range, --target,
/// --grid-width) when it cannot be built or a target would not be scored (too few frames in the
/// grid; unless auto_grid_width finds a width that works).
AspectCaseFiles MakeAspectCase(const AspectCase& c, const std::string& stem);

}  // namespace dualgrid::scenario
