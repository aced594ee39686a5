// The columns of a run folder's detections.csv and scans.csv (docs/output.md): one list, written
// by dualgrid::outputs (DetectionWriter, ScanWriter) in this order and read back by name by
// ReadRunFolder (run_folder.hpp).
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <string_view>

namespace dualgrid::recorded {

/// detections.csv: one row per radar detection per step; kDetectionColumns[c] names column c.
enum DetectionColumn : std::size_t {
  kDetStep,
  kDetTime,
  kDetSensor,
  kDetSensorName,
  kDetRange,
  kDetAzimuth,
  kDetRangeRate,
  kDetSnrDb,
  kDetXEgo,
  kDetYEgo,
  kDetX,
  kDetY,
  kDetRadialSpeed,
  kDetVrx,
  kDetVry,
  kDetSensorX,
  kDetSensorY,
  kDetSource,
  kDetIsClutter,
};
inline constexpr std::array<std::string_view, 19> kDetectionColumns = {
    "step",   "time",     "sensor",   "sensor_name", "range",      "azimuth",      "range_rate",
    "snr_db", "x_ego",    "y_ego",    "x",           "y",          "radial_speed", "vrx",
    "vry",    "sensor_x", "sensor_y", "source",      "is_clutter",
};
/// Appended with sensors.multipath on: each detection's path, bounces, reflector and ghost.
inline constexpr std::array<std::string_view, 4> kMultipathColumns = {"path", "bounces",
                                                                      "reflector", "ghost_of"};
/// Appended last with `--detections exact`: the source vehicle's SUMO vClass.
inline constexpr std::string_view kVClassColumn = "vclass";

/// scans.csv (with `--detections exact`): one row per step and scanning sensor; kScanColumns[c]
/// names column c.
enum ScanColumn : std::size_t {
  kScanStep,
  kScanTime,
  kScanSensor,
  kScanSensorName,
  kScanEgoX,
  kScanEgoY,
  kScanEgoYaw,
  kScanEgoVx,
  kScanEgoVy,
  kScanEgoYawRate,
  kScanEgoLength,
  kScanEgoWidth,
  kScanLaneYaw,
  kScanMountX,
  kScanMountY,
  kScanMountYaw,
  kScanFov,
  kScanMinRange,
  kScanMaxRange,
};
inline constexpr std::array<std::string_view, 19> kScanColumns = {
    "step",    "time",      "sensor",       "sensor_name", "ego_x",     "ego_y",    "ego_yaw",
    "ego_vx",  "ego_vy",    "ego_yaw_rate", "ego_length",  "ego_width", "lane_yaw", "mount_x",
    "mount_y", "mount_yaw", "fov",          "min_range",   "max_range",
};

/// The names joined by commas (a header row without its line end).
template <std::size_t N>
std::string JoinColumns(const std::array<std::string_view, N>& names) {
  std::string row;
  for (std::string_view n : names) {
    if (!row.empty()) row += ',';
    row += n;
  }
  return row;
}

}  // namespace dualgrid::recorded
