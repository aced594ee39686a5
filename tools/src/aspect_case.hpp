// `dualgrid tangential --kind aspect`: targets whose motion makes a chosen aspect angle with a
// chosen sensor's line of sight (docs/stress.md). Writes the scenario and its network (plain XML
// built with netconvert next to it).
#pragma once

#include <filesystem>
#include <string>

namespace dualgrid::tools {

struct AspectCase {
  std::string sensor = "front";  ///< one of the default rig's sensors
  double angle_deg = 90.0;       ///< aspect angle theta in [0, 180]: 0 receding along the LOS
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

/// Writes `out` (.yaml) and `out`'s stem + .nod.xml/.edg.xml/.net.xml beside it, building the
/// network with netconvert. Throws std::invalid_argument when a target would not be scored (too
/// few frames in the grid; unless auto_grid_width finds a width that works), naming what to
/// change; std::runtime_error when netconvert fails.
/// Returns a summary line of the geometry.
std::string WriteAspectCase(const AspectCase& c, const std::filesystem::path& out);

}  // namespace dualgrid::tools
