// Conversions between SUMO's conventions and dualgrid's (docs/frames.md).
#pragma once

#include "dualgrid/core/types.hpp"

namespace dualgrid::sim {

/// SUMO angle [deg], clockwise from north (+y), to yaw [rad], counter-clockwise from +x, in
/// (-pi, pi].
inline double SumoAngleToYaw(double sumo_deg) { return WrapAngle(DegToRad(90.0 - sumo_deg)); }

/// Inverse of SumoAngleToYaw, in [0, 360).
inline double YawToSumoAngle(double yaw) {
  double deg = 90.0 - RadToDeg(yaw);
  deg = std::fmod(deg, 360.0);
  return deg < 0.0 ? deg + 360.0 : deg;
}

/// SUMO reports the front-bumper centre; the box centre lies half a length behind it.
inline Position FrontBumperToCenter(const Position& front, double yaw, double length) {
  return front - 0.5 * length * UnitVector(yaw);
}

/// Inverse of FrontBumperToCenter.
inline Position CenterToFrontBumper(const Position& center, double yaw, double length) {
  return center + 0.5 * length * UnitVector(yaw);
}

/// World velocity from SUMO's longitudinal speed along the lane direction `lane_yaw` and its
/// lateral speed (positive to the left of the lane direction, as SUMO's getLateralSpeed).
inline Velocity LaneSpeedsToVelocity(double speed, double lateral_speed, double lane_yaw) {
  return speed * UnitVector(lane_yaw) + lateral_speed * UnitVector(lane_yaw + 0.5 * kPi);
}

}  // namespace dualgrid::sim
