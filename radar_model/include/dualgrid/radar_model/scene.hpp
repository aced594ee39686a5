// What the radar model sees (world frame) and what it reports.
#pragma once

#include <vector>

#include "dualgrid/core/types.hpp"
#include "dualgrid/radar_model/multipath.hpp"

namespace dualgrid::radar {

/// A vehicle or parked box. Parked boxes have zero velocity and yaw rate. Ids must be unique
/// across targets and polylines (they become Detection::source_id).
struct Target {
  int id = 0;
  OrientedBox box{};
  Velocity velocity = Velocity::Zero();  ///< of the box centre [m/s]
  double yaw_rate = 0.0;                 ///< [rad/s]
  double rcs_dbsm = 10.0;                ///< whole-vehicle RCS, shared among its scatterers
};

/// A thin static structure (guard rail): scatters along its segments and occludes.
struct Polyline {
  int id = 0;
  std::vector<Position> points;
  double rcs_dbsm_per_metre = -5.0;  ///< RCS per metre of length [dBsm/m]
};

/// Everything around the ego. The ego itself must not be part of it (targets whose box
/// contains a sensor are ignored for that sensor anyway).
struct Scene {
  std::vector<Target> targets;
  std::vector<Polyline> polylines;
};

/// Ego state in the world frame; velocity is that of the ego box centre (pose.position).
struct EgoMotion {
  Pose2 pose{};
  Velocity velocity = Velocity::Zero();
  double yaw_rate = 0.0;
  /// The ego's own body, a box centred on pose [m]: it hides what lies behind it from sensors
  /// mounted on it (a line of sight running more than 5 cm inside it is blocked). 0: no body.
  double length = 0.0;
  double width = 0.0;
};

/// One radar detection.
struct Detection {
  int sensor = 0;           ///< index into RadarModel::sensors()
  double range = 0.0;       ///< measured [m]
  double azimuth = 0.0;     ///< measured, sensor frame [rad]
  double range_rate = 0.0;  ///< measured, uncompensated (relative to the moving sensor) [m/s]
  double snr_db = 0.0;      ///< noise-free SNR of the resolution cell [dB]
  Position position_ego = Position::Zero();
  Position position_world = Position::Zero();
  /// Radial speed over ground: range_rate + sensor velocity . line of sight (0 for static).
  double radial_speed_compensated = 0.0;
  /// radial_speed_compensated times the world line-of-sight unit vector (paper eq. (1)).
  Velocity radial_velocity_world = Velocity::Zero();
  Position sensor_position_world = Position::Zero();
  /// Target or polyline id of the strongest scatterer of the cell when it is a direct return;
  /// -1 for clutter and for ghosts (a ghost is never its object: see ghost_of).
  int source_id = -1;
  bool is_clutter = false;
  /// Multipath labels of the strongest scatterer (docs/radar.md, "Multipath"): the path, its
  /// number of bounces (1 direct and clutter, 2 or 3), the mirror's polyline or target id and
  /// the real object whose ghost it is (-1 when direct).
  Path path = Path::kDirect;
  int bounces = 1;
  int reflector_id = -1;
  int ghost_of = -1;
};

}  // namespace dualgrid::radar
