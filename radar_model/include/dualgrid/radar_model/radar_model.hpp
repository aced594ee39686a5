// The radar model: scatterers on boxes and guard rails, occlusion, resolution-cell merging,
// SNR-driven detection and noise, false alarms, ego-motion compensation.
#pragma once

#include <cstdint>
#include <vector>

#include "dualgrid/radar_model/multipath.hpp"
#include "dualgrid/radar_model/scene.hpp"
#include "dualgrid/radar_model/sensor_model.hpp"
#include "dualgrid/radar_model/sensor_params.hpp"

namespace dualgrid::radar {

/// Switches for the individual effects (YAML: sensors: {noise, false_alarms, occlusion,
/// multipath}).
struct ModelOptions {
  bool noise = true;          ///< measurement noise on range, azimuth, range rate
  bool false_alarms = true;   ///< clutter detections
  bool occlusion = true;      ///< nearer boxes / rails hide scatterers behind them
  MultipathParams multipath;  ///< ghosts off rails and truck flanks (off by default)
};

/// A point scatterer as seen by one sensor (after field of view, range, range-rate window and
/// occlusion), before resolution-cell merging: a direct return or a multipath ghost of one point
/// of a box. Exposed for tests and diagnostics.
struct Scatterer {
  /// World; for a ghost, where the radar places it (its path's range along its arrival
  /// direction).
  Position position = Position::Zero();
  Velocity velocity = Velocity::Zero();  ///< world, over ground, of the real scattering point
  /// Linear share of the source's RCS [m^2]; for a ghost times its path's losses, so that
  /// SensorModel::SnrLinear(rcs_m2, truth.range) is the path's SNR.
  double rcs_m2 = 0.0;
  Polar truth{};       ///< noise-free polar in the sensor frame (a ghost's apparent one)
  int source_id = -1;  ///< the real object (target or polyline id)
  Path path = Path::kDirect;
  int bounces = 1;                     ///< 1 direct, 2 or 3 for a ghost
  int reflector_id = -1;               ///< the mirror's polyline or target id; -1 direct
  Position origin = Position::Zero();  ///< the real scattering point, world
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
  /// Resolution-cell merging, detection test, noise and false alarms of one sensor's
  /// scatterers, appended to *out.
  void Detect(int sensor, const EgoMotion& ego, const std::vector<Scatterer>& scatterers,
              std::uint64_t step, std::vector<Detection>* out) const;

  std::vector<SensorParams> params_;
  std::vector<SensorModel> models_;
  ModelOptions options_;
  std::uint64_t seed_;
};

}  // namespace dualgrid::radar
