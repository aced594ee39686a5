// The radar model: scatterers on boxes and guard rails, occlusion, resolution-cell merging,
// SNR-driven detection and noise, false alarms, ego-motion compensation.
#pragma once

#include <cstdint>
#include <vector>

#include "dualgrid/radar_model/scene.hpp"
#include "dualgrid/radar_model/sensor_model.hpp"
#include "dualgrid/radar_model/sensor_params.hpp"

namespace dualgrid::radar {

/// Switches for the individual effects (YAML: radar: {noise, false_alarms, occlusion}).
struct ModelOptions {
  bool noise = true;         ///< measurement noise on range, azimuth, range rate
  bool false_alarms = true;  ///< clutter detections
  bool occlusion = true;     ///< nearer boxes / rails hide scatterers behind them
};

/// A point scatterer as seen by one sensor (after field of view, range, range-rate window and
/// occlusion), before resolution-cell merging. Exposed for tests and diagnostics.
struct Scatterer {
  Position position = Position::Zero();  ///< world
  Velocity velocity = Velocity::Zero();  ///< world, over ground
  double rcs_m2 = 0.0;                   ///< linear share of the source's RCS
  Polar truth{};                         ///< noise-free polar in the sensor frame
  int source_id = -1;
};

class RadarModel {
 public:
  /// Throws std::invalid_argument naming the sensor and field if a sensor is invalid.
  RadarModel(std::vector<SensorParams> sensors, ModelOptions options, std::uint64_t seed);

  const std::vector<SensorParams>& sensors() const { return params_; }
  const std::vector<SensorModel>& sensor_models() const { return models_; }
  const ModelOptions& options() const { return options_; }

  /// Sensor `sensor`'s world pose given the ego pose.
  Pose2 SensorPose(int sensor, const Pose2& ego_pose) const;
  /// All sensors' world poses, in sensor order.
  std::vector<Pose2> SensorPoses(const Pose2& ego_pose) const;

  /// Sensors that fire at the step ending at `time` [s]: sensor i fires if a multiple of its
  /// update_period lies in (time - step_length, time] (1e-9 period tolerance), so every sensor
  /// fires at time 0 and at most once per step.
  std::vector<int> SensorsDue(double time, double step_length) const;

  /// Detections of all sensors due at this step, ordered by sensor, then resolution cell,
  /// then clutter. Deterministic in (seed, step) whatever the OpenMP thread count.
  std::vector<Detection> Scan(const EgoMotion& ego, const Scene& scene, std::uint64_t step,
                              double time, double step_length) const;
  /// Detections of one sensor regardless of its update period.
  std::vector<Detection> ScanSensor(int sensor, const EgoMotion& ego, const Scene& scene,
                                    std::uint64_t step) const;
  /// Visible scatterers of one sensor (no merging, detection test, noise or clutter).
  std::vector<Scatterer> VisibleScatterers(int sensor, const EgoMotion& ego,
                                           const Scene& scene) const;

 private:
  void CheckSensor(int sensor) const;

  std::vector<SensorParams> params_;
  std::vector<SensorModel> models_;
  ModelOptions options_;
  std::uint64_t seed_;
};

}  // namespace dualgrid::radar
