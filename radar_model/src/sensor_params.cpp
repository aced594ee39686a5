#include "dualgrid/radar_model/sensor_params.hpp"

#include <cmath>
#include <stdexcept>

namespace dualgrid::radar {
namespace {

// Resolution-cell indices are packed 20 bits per dimension (radar_model.cpp).
constexpr double kMaxBins = 1 << 20;

bool Fail(std::string* error, const std::string& message) {
  if (error != nullptr) *error = message;
  return false;
}

}  // namespace

bool SensorParams::IsValid(std::string* error) const {
  const auto finite = [](double v) { return std::isfinite(v); };
  if (name.empty()) return Fail(error, "name: must not be empty");
  if (!finite(mount.position.x()) || !finite(mount.position.y()) || !finite(mount.yaw))
    return Fail(error, "mount: must be finite");
  if (!finite(fov) || fov <= 0.0 || fov > 2.0 * kPi)
    return Fail(error, "fov: must be in (0, 2 pi] rad (full azimuth field of view)");
  if (!finite(min_range) || min_range < 0.0) return Fail(error, "min_range: must be >= 0 m");
  if (!finite(max_range) || max_range <= min_range)
    return Fail(error, "max_range: must be finite and > min_range");
  if (!finite(min_range_rate)) return Fail(error, "min_range_rate: must be finite");
  if (!finite(max_range_rate) || max_range_rate <= min_range_rate)
    return Fail(error, "max_range_rate: must be finite and > min_range_rate");
  if (!finite(range_resolution) || range_resolution <= 0.0 ||
      max_range / range_resolution >= kMaxBins)
    return Fail(error, "range_resolution: must be > 0 and give fewer than 2^20 range cells");
  if (!finite(azimuth_resolution) || azimuth_resolution <= 0.0 ||
      fov / azimuth_resolution >= kMaxBins)
    return Fail(error, "azimuth_resolution: must be > 0 and give fewer than 2^20 azimuth cells");
  if (!finite(range_rate_resolution) || range_rate_resolution <= 0.0 ||
      (max_range_rate - min_range_rate) / range_rate_resolution >= kMaxBins)
    return Fail(error,
                "range_rate_resolution: must be > 0 and give fewer than 2^20 range-rate cells");
  if (!finite(range_bias_fraction) || range_bias_fraction < 0.0)
    return Fail(error, "range_bias_fraction: must be >= 0");
  if (!finite(azimuth_bias_fraction) || azimuth_bias_fraction < 0.0)
    return Fail(error, "azimuth_bias_fraction: must be >= 0");
  if (!finite(range_rate_bias_fraction) || range_rate_bias_fraction < 0.0)
    return Fail(error, "range_rate_bias_fraction: must be >= 0");
  if (!finite(reference_range) || reference_range <= 0.0)
    return Fail(error, "reference_range: must be > 0 m");
  if (!finite(reference_rcs_dbsm)) return Fail(error, "reference_rcs_dbsm: must be finite");
  if (!finite(false_alarm_rate) || false_alarm_rate <= 0.0 || false_alarm_rate >= 0.5)
    return Fail(error, "false_alarm_rate: must be in (0, 0.5)");
  if (!finite(reference_pd) || reference_pd <= false_alarm_rate || reference_pd >= 1.0)
    return Fail(error, "reference_pd: must be in (false_alarm_rate, 1)");
  if (!finite(update_period) || update_period <= 0.0)
    return Fail(error, "update_period: must be > 0 s");
  return true;
}

SensorParams DefaultShortRangeRadar() {
  SensorParams p;  // the struct defaults are the corner radar (sources in docs/radar.md)
  p.name = "short_range";
  return p;
}

SensorParams DefaultLongRangeRadar() {
  SensorParams p;
  p.name = "long_range";
  // Delphi ESR long-range mode: 20 deg FOV, 1..174 m, -100..+40 m/s, 50 ms.
  p.fov = DegToRad(20.0);
  p.min_range = 1.0;
  p.max_range = 174.0;
  p.min_range_rate = -100.0;
  p.max_range_rate = 40.0;
  // Continental ARS408-21 far-range resolutions.
  p.range_resolution = 1.79;
  p.azimuth_resolution = DegToRad(1.6);
  p.range_rate_resolution = 0.37 / 3.6;
  p.reference_range = 174.0;
  p.update_period = 0.05;
  return p;
}

std::vector<SensorParams> DefaultRig(double ego_length, double ego_width) {
  if (!(ego_length > 0.0) || !(ego_width > 0.0) || !std::isfinite(ego_length) ||
      !std::isfinite(ego_width))
    throw std::invalid_argument("DefaultRig: ego_length and ego_width must be positive, got " +
                                std::to_string(ego_length) + " x " + std::to_string(ego_width));
  const double x = 0.3 * ego_length, y = 0.5 * ego_width;
  struct Corner {
    const char* name;
    double x, y, yaw_deg;
  };
  const Corner corners[] = {{"front_left", x, y, 45.0},
                            {"front_right", x, -y, -45.0},
                            {"rear_left", -x, y, 135.0},
                            {"rear_right", -x, -y, -135.0}};
  std::vector<SensorParams> rig;
  for (const Corner& c : corners) {
    SensorParams p = DefaultShortRangeRadar();
    p.name = c.name;
    p.mount = Pose2{Position(c.x, c.y), DegToRad(c.yaw_deg)};
    rig.push_back(p);
  }
  SensorParams front = DefaultLongRangeRadar();
  front.name = "front";
  front.mount = Pose2{Position(0.5 * ego_length, 0.0), 0.0};
  rig.push_back(front);
  return rig;
}

}  // namespace dualgrid::radar
