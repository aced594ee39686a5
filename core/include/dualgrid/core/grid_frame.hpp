// The frame the occupancy grid lives in (docs/frames.md, "Grid frame").
//
// The filter works in its own Cartesian frame whose axes are the grid's: cells are square and
// axis-aligned there, and the grid moves by whole cells. GridFrame relates that frame to SUMO's
// world frame by a rotation about the world origin by `yaw` [rad] (the grid's +x axis points
// along world heading `yaw`). No translation: positions keep their magnitude.
//
// Invariant: with yaw == 0 every map is the identity bit for bit (no arithmetic at all), so
// scenarios whose grid frame is the world frame give exactly the results of a world-fixed grid.
#pragma once

#include <cmath>
#include <optional>

#include "dualgrid/core/types.hpp"

namespace dualgrid {

class GridFrame {
 public:
  GridFrame() = default;
  /// Grid axes turned by `yaw` [rad] from the world's (counter-clockwise).
  explicit GridFrame(double yaw)
      : yaw_(yaw), c_(yaw == 0.0 ? 1.0 : std::cos(yaw)), s_(yaw == 0.0 ? 0.0 : std::sin(yaw)) {}

  double yaw() const { return yaw_; }
  bool identity() const { return yaw_ == 0.0; }

  /// World point [m] -> grid frame [m].
  Position ToGrid(const Position& w) const {
    if (identity()) return w;
    return {c_ * w.x() + s_ * w.y(), -s_ * w.x() + c_ * w.y()};
  }
  /// Grid-frame point [m] -> world [m].
  Position ToWorld(const Position& g) const {
    if (identity()) return g;
    return {c_ * g.x() - s_ * g.y(), s_ * g.x() + c_ * g.y()};
  }
  /// Free vectors (velocities [m/s], offsets [m]) rotate like points about the origin.
  Vector2 VectorToGrid(const Vector2& v) const { return ToGrid(v); }
  Vector2 VectorToWorld(const Vector2& v) const { return ToWorld(v); }
  /// Headings [rad].
  double YawToGrid(double world_yaw) const {
    return identity() ? world_yaw : WrapAngle(world_yaw - yaw_);
  }
  double YawToWorld(double grid_yaw) const {
    return identity() ? grid_yaw : WrapAngle(grid_yaw + yaw_);
  }
  Pose2 ToGrid(const Pose2& p) const { return {ToGrid(p.position), YawToGrid(p.yaw)}; }
  OrientedBox ToGrid(const OrientedBox& b) const {
    return {ToGrid(b.center), YawToGrid(b.yaw), b.length, b.width};
  }

 private:
  double yaw_ = 0.0;
  double c_ = 1.0, s_ = 0.0;
};

/// A grid yaw [rad] along `heading` [rad]: the heading itself, except that a heading within
/// 1e-3 deg of a whole degree is that whole degree. SUMO's headings of roads along a world axis
/// carry ~1e-6 deg of rounding (an eastbound lane reads 89.99999... deg): snapped, such roads get
/// exactly axis-aligned grids (GridFrame's identity at 0, bit for bit), while every other road
/// gets a grid exactly along it, whatever the network's own orientation.
inline double GridYawAlong(double heading) {
  const double deg = RadToDeg(heading), whole = std::round(deg);
  const double yaw = std::abs(deg - whole) < 1e-3 ? DegToRad(whole) : heading;
  return WrapAngle(yaw) == 0.0 ? 0.0 : yaw;
}

/// The grid that follows the ego (docs/algorithm.md, "Grid frame"): the yaw [rad] to turn the
/// grid to, GridYawAlong(heading), once `heading` [rad] has drifted from `grid_yaw` [rad] by more
/// than `threshold` [rad] (> 0); std::nullopt while it has not. Depends on the angle between the
/// two only (up to the snap), so a scene turned as a whole turns its grid at the same moments.
inline std::optional<double> RealignedYaw(double grid_yaw, double heading, double threshold) {
  if (!(std::abs(WrapAngle(heading - grid_yaw)) > threshold)) return std::nullopt;
  return GridYawAlong(heading);
}

}  // namespace dualgrid
