// The guard-rail stress case (`dualgrid tangential --kind guardrail`, docs/stress.md): the ego
// beside a guard rail with vehicles passing on the other side of it, for multipath. The rail is
// the only obstacle, so every ghost in the run is a ghost off it (or off a passing truck's flank).
// Pure: it returns the scenario's text.
#pragma once

#include <cstdint>
#include <string>

namespace dualgrid::scenario {

struct GuardRailCase {
  double offset = 3.75;     ///< ego centre line -> rail [m] (3.75: the highway's median rail)
  double rail_angle = 0.0;  ///< the rail's aspect to the road [deg], + turning away ahead
  double ego_speed = 20.0;  ///< [m/s], fixed
  double speed = 25.0;      ///< passing vehicles' speed over ground [m/s]
  int count = 4;            ///< passing vehicles (every third a truck)
  double spacing = 50.0;    ///< between passing vehicles of one lane [m]
  std::uint64_t seed = 1;
};

/// The scenario's text (header comment with the command and the geometry, network `highway`).
/// Throws std::invalid_argument naming the option when the case cannot be built: a speed too
/// close to the ego's (nobody passes), a run longer than the road, spacing below SUMO's
/// insertion gap, a rail angle that brings the rail into the ego's lane at the pivot.
std::string GuardRailScenario(const GuardRailCase& c);

}  // namespace dualgrid::scenario
