// Detection statistics of one sensor: radar equation, ROC, resolution-limited noise (the
// MATLAB statistical radar model family; equations in docs/radar.md).
#pragma once

#include <optional>
#include <vector>

#include "dualgrid/core/random.hpp"
#include "dualgrid/radar_model/sensor_params.hpp"

namespace dualgrid::radar {

/// Inverse complementary error function on (0, 2). Throws std::domain_error outside.
double ErfcInv(double y);

/// Non-fluctuating ROC: Pd = 0.5 erfc(erfcinv(2 Pfa) - sqrt(snr)), snr linear.
double DetectionProbability(double snr_linear, double false_alarm_rate);

/// Linear SNR at which DetectionProbability(snr, pfa) == pd (pd > pfa).
double RequiredSnr(double pd, double false_alarm_rate);

/// A polar measurement in the sensor frame.
struct Polar {
  double range = 0.0;       ///< [m]
  double azimuth = 0.0;     ///< [rad]
  double range_rate = 0.0;  ///< [m/s]
};

/// Per-sensor constants of the detection model, precomputed from SensorParams.
class SensorModel {
 public:
  /// Throws std::invalid_argument if the parameters are invalid.
  explicit SensorModel(const SensorParams& params);

  const SensorParams& params() const { return params_; }
  /// G in SNR_dB = G + RCS_dB - 40 log10(R): the reference target at the reference range
  /// gets exactly the SNR that gives reference_pd at false_alarm_rate.
  double loop_gain_db() const { return loop_gain_db_; }
  double SnrDb(double rcs_dbsm, double range) const;
  /// Linear SNR of a scatterer with linear RCS [m^2] at range [m] (hot path, no logs).
  double SnrLinear(double rcs_m2, double range) const {
    const double r2 = range * range;
    return loop_gain_linear_ * rcs_m2 / (r2 * r2);
  }
  double DetectionProbabilityAt(double snr_linear) const;
  /// Standard deviations at a linear SNR: the SNR term of MATLAB's model plus the accuracy
  /// floor a in quadrature, sigma_R = sqrt(dR^2 12 / (8 pi^2 SNR) + a_R^2),
  /// sigma_az = sqrt(dAz(az)^2 / (1.6^2 2 SNR) + a_az(az)^2) with the off-boresight profile at
  /// azimuth az [rad], sigma_rr = sqrt(dRR^2 6 / ((2 pi)^2 SNR) + a_rr^2).
  double RangeSigma(double snr_linear) const;
  double AzimuthSigma(double snr_linear, double azimuth = 0.0) const;
  double RangeRateSigma(double snr_linear) const;
  /// Azimuth resolution cell of `azimuth` [rad]: cells are azimuth_resolution wide at boresight
  /// and widen off boresight with the profile; one cell edge lies on the boresight.
  std::uint64_t AzimuthCell(double azimuth) const;
  /// Azimuth cells touching the field of view (the outermost ones reach beyond it).
  int AzimuthCells() const { return static_cast<int>(azimuth_edges_.size()) - 1; }
  /// Azimuth cells inside the field of view, the outermost counted by the share of them inside
  /// it (fov / azimuth_resolution without an off-boresight profile): the false-alarm count.
  double AzimuthCellsInView() const { return cells_in_view_; }
  /// Number of (range, azimuth, range-rate) resolution cells in the sensor's window.
  double ResolutionCellCount() const;
  /// Expected false alarms per scan: cells times false_alarm_rate.
  double ExpectedFalseAlarms() const { return ResolutionCellCount() * params_.false_alarm_rate; }
  /// SNR [dB] reported for false alarms: the detection threshold erfcinv(2 Pfa)^2.
  double ThresholdSnrDb() const { return threshold_snr_db_; }
  /// True if `p` is inside the range, azimuth and range-rate window.
  bool InWindow(const Polar& p) const;

  /// Detection test and noise for one resolution cell with true polar `truth` and linear SNR:
  /// draws one uniform (detected if < Pd) then, if `noise`, three normals. nullopt if missed or
  /// if the noisy measurement leaves the sensor's window (the sensor would not report it).
  std::optional<Polar> Measure(const Polar& truth, double snr_linear, bool noise,
                               CounterRng& rng) const;

 private:
  SensorParams params_;
  double erfcinv_2pfa_ = 0.0;
  double loop_gain_db_ = 0.0;
  double loop_gain_linear_ = 0.0;
  double threshold_snr_db_ = 0.0;
  std::vector<double> azimuth_edges_;  // increasing, from <= -fov/2 to >= fov/2 [rad]
  double cells_in_view_ = 0.0;
};

}  // namespace dualgrid::radar
