// Ground truth of one simulation step, in the world frame (docs/frames.md).
#pragma once

#include <string>
#include <vector>

#include "dualgrid/core/types.hpp"

namespace dualgrid::sim {

struct VehicleState {
  std::string id;
  std::string type;
  OrientedBox box;                       ///< centre [m], yaw [rad], length and width [m]
  Velocity velocity = Velocity::Zero();  ///< [m/s] of the box centre, lateral motion included
  double yaw_rate = 0.0;                 ///< [rad/s]
  double speed = 0.0;                    ///< [m/s] SUMO's longitudinal speed
  double lateral_speed = 0.0;            ///< [m/s] SUMO's lateral speed (lane changes), + left
  std::string lane;                      ///< SUMO lane id
  /// Direction of its lane at the box centre [rad]: the road's direction, without the tilt of
  /// the vehicle's heading during a lane change (the box's yaw when the lane has no shape).
  double lane_yaw = 0.0;
  double rcs_dbsm = 10.0;
};

struct Frame {
  int step = 0;
  double time = 0.0;  ///< [s] run time (since the scenario's begin) at the end of the step
  VehicleState ego;
  std::vector<VehicleState> vehicles;  ///< all others, sorted by id (deterministic order)

  /// The ego pose as a frame: origin at the ego box centre, x forward, y left.
  Pose2 EgoPose() const { return {ego.box.center, ego.box.yaw}; }
};

}  // namespace dualgrid::sim
