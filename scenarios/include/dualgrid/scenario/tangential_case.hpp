// The crossing and parallel tangential-motion stress cases (`dualgrid tangential`, docs/stress.md):
// vehicles moving perpendicular to a radar's line of sight, where the Doppler sees (almost)
// nothing of their speed (the paper's Fig. 3 cases).
//   crossing: on the `crossing` network, vehicles cross the ego's road ahead of it at right
//             angles, perpendicular to the front radar's boresight;
//   parallel: on the `highway` network, vehicles drive alongside the ego in both adjacent lanes
//             at nearly its speed, perpendicular to the corner radars' lines of sight.
// Pure: it returns the scenario's text.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace dualgrid::scenario {

struct TangentialCase {
  std::string kind = "crossing";  ///< "crossing" or "parallel" ("guardrail" for Speed/Spacing)
  int count = 4;                  ///< stress vehicles
  double ego_speed = 20.0;        ///< [m/s], fixed
  /// Stress vehicles' speed over ground [m/s]; unset: Speed()'s default for the kind.
  std::optional<double> speed;
  double first_distance = 30.0;  ///< crossing: distance ahead of the ego of the first crossing [m]
  /// Crossing: distance between crossings; parallel, guardrail: between vehicles of a lane [m].
  /// Unset: Spacing()'s default for the kind.
  std::optional<double> spacing;
  std::uint64_t seed = 1;

  /// `speed`, or the kind's default [m/s]: crossing 15, parallel ego + 0.3 (they stay
  /// alongside), guardrail ego + 5 (they pass).
  double Speed() const;
  /// `spacing`, or the kind's default [m]: crossing 20, parallel 40, guardrail 50.
  double Spacing() const;
};

/// The scenario's text (header comment with the generating command, network `crossing` or
/// `highway`). Throws std::invalid_argument naming the command-line option when the case cannot
/// be built: another kind, a parked ego, parallel traffic that would not stay alongside, spacing
/// below SUMO's insertion gap, a crossing car too fast to be scored, crossings beyond the approach.
std::string TangentialScenario(const TangentialCase& c);

}  // namespace dualgrid::scenario
