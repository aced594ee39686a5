// Parameters of one radar sensor and the default five-radar rig (docs/radar.md cites every value).
#pragma once

#include <string>
#include <vector>

#include "dualgrid/core/types.hpp"

namespace dualgrid::radar {

/// One radar sensor. Field names are the YAML keys (see docs/radar.md); angles in radians.
/// Defaults describe a corner short-range radar (Delphi SRR2-like limits, ARS408 near-range
/// resolutions) mounted at the ego origin facing forward.
struct SensorParams {
  std::string name = "radar";
  /// Mounting pose in the ego frame (YAML: mount_x, mount_y, mount_yaw).
  Pose2 mount{};
  /// Full azimuth field of view [rad], centred on the boresight (sensor x axis).
  double fov = DegToRad(150.0);
  double min_range = 0.5;   ///< [m]
  double max_range = 80.0;  ///< [m]
  /// Range-rate window [m/s] (negative = approaching); outside it a return is dropped.
  double min_range_rate = -400.0 / 3.6;
  double max_range_rate = 200.0 / 3.6;
  double range_resolution = 0.39;             ///< [m]
  double azimuth_resolution = DegToRad(3.2);  ///< [rad]
  double range_rate_resolution = 0.43 / 3.6;  ///< [m/s]
  /// Accuracy floors (1 sigma at high SNR; data-sheet "accuracy"), docs/radar.md step 9. The
  /// azimuth values hold at boresight and grow off boresight by the profile below.
  double range_accuracy = 0.10;             ///< [m]
  double azimuth_accuracy = DegToRad(0.3);  ///< [rad]
  double range_rate_accuracy = 0.10;        ///< [m/s]
  /// Off-boresight profile: at |azimuth| = off_boresight[k] [rad] the azimuth resolution is
  /// off_boresight_resolution[k] times azimuth_resolution and the azimuth accuracy
  /// off_boresight_accuracy[k] times azimuth_accuracy; linear in between, constant beyond the
  /// last point, factor 1 before the first. Empty: the same everywhere. Defaults: ARS408-21 near
  /// range (3.2 / 4.5 / 12.3 deg resolution and 0.3 / 1 / 5 deg accuracy at 0 / 45 / 60 deg).
  std::vector<double> off_boresight = {0.0, DegToRad(45.0), DegToRad(60.0)};
  std::vector<double> off_boresight_resolution = {1.0, 4.5 / 3.2, 12.3 / 3.2};
  std::vector<double> off_boresight_accuracy = {1.0, 1.0 / 0.3, 5.0 / 0.3};
  /// Detection model: a reference_rcs_dbsm target at reference_range is detected with
  /// probability reference_pd at false-alarm probability false_alarm_rate per resolution cell.
  double reference_range = 80.0;     ///< [m]
  double reference_rcs_dbsm = 10.0;  ///< [dBsm]
  double reference_pd = 0.9;
  double false_alarm_rate = 1e-6;
  double update_period = 0.05;  ///< [s]

  /// False with a message naming the offending field (Ceres style) if a value is out of range.
  bool IsValid(std::string* error) const;

  /// Azimuth resolution [rad] / accuracy floor [rad] at azimuth `az` [rad] (sensor frame).
  double AzimuthResolutionAt(double az) const;
  double AzimuthAccuracyAt(double az) const;
};

/// Accuracy floors of the default sensors. kDataSheet: the data-sheet accuracies with the
/// azimuth degrading off boresight (the default); kClean: the earlier idealised floors (MATLAB's
/// default bias fractions of the resolutions: 5 % range, 10 % azimuth, 5 % range rate), the
/// same over the whole field of view.
enum class Accuracy { kDataSheet, kClean };

/// The paper's rig: four corner short-range radars at the wheel positions ("front_left",
/// "front_right", "rear_left", "rear_right", facing +-45 deg / +-135 deg) and the long-range
/// "front" radar at the front bumper centre. Wheel positions: x = +-0.3 ego_length (a typical
/// 2.7 m wheelbase on a 4.5 m car), y = +-0.5 ego_width. Throws std::invalid_argument on
/// non-positive dimensions.
std::vector<SensorParams> DefaultRig(double ego_length, double ego_width,
                                     Accuracy accuracy = Accuracy::kDataSheet);

/// Corner short-range radar defaults (mount left at the origin).
SensorParams DefaultShortRangeRadar(Accuracy accuracy = Accuracy::kDataSheet);
/// Front long-range radar defaults (mount left at the origin).
SensorParams DefaultLongRangeRadar(Accuracy accuracy = Accuracy::kDataSheet);

/// The sensor's pose in the world frame given the ego pose.
inline Pose2 SensorWorldPose(const SensorParams& sensor, const Pose2& ego_pose) {
  return ego_pose.Compose(sensor.mount);
}

}  // namespace dualgrid::radar
