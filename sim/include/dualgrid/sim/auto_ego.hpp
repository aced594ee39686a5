// `ego: {from_routes: auto}`: which vehicle of the user's SUMO files becomes the ego, by a first
// run of SUMO over the run's time window (docs/scenarios.md, "The auto ego").
#pragma once

#include <cstddef>
#include <string>

#include "dualgrid/core/types.hpp"

namespace dualgrid::sim {

/// The grid's rectangle around a vehicle in its heading frame [m]: `ahead` of it, `behind` it,
/// to its `left` and `right` (the loader fills it from filter.length_x, width_y, ahead, left).
struct ViewBox {
  double ahead = 100.0, behind = 100.0, left = 12.5, right = 12.5;
  /// Whether `offset` (other minus this vehicle, world frame [m]) lies in the box of a vehicle
  /// heading `yaw` [rad].
  bool Contains(const Vector2& offset, double yaw) const;
};

/// What the first run found for the chosen vehicle, and why it won (summary.json `ego_choice`).
struct AutoEgoChoice {
  std::string id;
  double seen_s = 0.0;           ///< [s] time with another vehicle in its ViewBox
  double in_run_s = 0.0;         ///< [s] time in the run (to its arrival, or the end)
  double depart_s = 0.0;         ///< [s, SUMO time] its departure
  std::size_t candidates = 0;    ///< road vehicles of the files that departed in the run
  std::size_t with_traffic = 0;  ///< of which ever had another vehicle in their ViewBox
  /// The rule and the numbers, in one sentence; says that nothing can be scored when no
  /// candidate ever had traffic in its grid (a scene of one vehicle).
  std::string Reason() const;
};

}  // namespace dualgrid::sim
