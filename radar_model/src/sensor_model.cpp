#include "dualgrid/radar_model/sensor_model.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <iterator>
#include <stdexcept>

namespace dualgrid::radar {

double ErfcInv(double y) {
  if (!(y > 0.0 && y < 2.0)) throw std::domain_error("ErfcInv: argument must be in (0, 2)");
  if (y > 1.0) return -ErfcInv(2.0 - y);  // erfc(-x) = 2 - erfc(x)
  // Newton on log(erfc(x)) - log(y): log erfc is concave and decreasing on x >= 0, so starting
  // at x = 0 the iterates overshoot once and then decrease monotonically to the root.
  const double log_y = std::log(y);
  const double two_over_sqrt_pi = 2.0 / std::sqrt(kPi);
  double x = 0.0;
  for (int i = 0; i < 100; ++i) {
    const double e = std::erfc(x);
    const double f = std::log(e) - log_y;
    const double df = -two_over_sqrt_pi * std::exp(-x * x) / e;
    const double step = f / df;
    x -= step;
    if (std::abs(step) <= 1e-15 * std::max(1.0, std::abs(x))) break;
  }
  return x;
}

double DetectionProbability(double snr_linear, double false_alarm_rate) {
  return 0.5 * std::erfc(ErfcInv(2.0 * false_alarm_rate) - std::sqrt(std::max(snr_linear, 0.0)));
}

double RequiredSnr(double pd, double false_alarm_rate) {
  const double root = ErfcInv(2.0 * false_alarm_rate) - ErfcInv(2.0 * pd);
  if (!(root > 0.0)) throw std::invalid_argument("RequiredSnr: pd must exceed false_alarm_rate");
  return root * root;
}

SensorModel::SensorModel(const SensorParams& params) : params_(params) {
  std::string error;
  if (!params_.IsValid(&error))
    throw std::invalid_argument("radar sensor '" + params_.name + "': " + error);
  erfcinv_2pfa_ = ErfcInv(2.0 * params_.false_alarm_rate);
  const double reference_snr_db =
      10.0 * std::log10(RequiredSnr(params_.reference_pd, params_.false_alarm_rate));
  loop_gain_db_ =
      reference_snr_db - params_.reference_rcs_dbsm + 40.0 * std::log10(params_.reference_range);
  loop_gain_linear_ = std::pow(10.0, 0.1 * loop_gain_db_);
  threshold_snr_db_ = 20.0 * std::log10(erfcinv_2pfa_);
  // Azimuth cell edges outwards from the boresight, each cell as wide as the resolution at its
  // middle (one step of the midpoint rule), mirrored to the other side.
  std::vector<double> half = {0.0};
  while (half.back() < 0.5 * params_.fov) {
    const double e = half.back();
    half.push_back(e + params_.AzimuthResolutionAt(e + 0.5 * params_.AzimuthResolutionAt(e)));
  }
  azimuth_edges_.clear();
  for (std::size_t k = half.size(); k-- > 1;) azimuth_edges_.push_back(-half[k]);
  azimuth_edges_.insert(azimuth_edges_.end(), half.begin(), half.end());
  const double h = 0.5 * params_.fov;
  cells_in_view_ = 0.0;
  for (std::size_t k = 0; k + 1 < azimuth_edges_.size(); ++k) {
    const double lo = azimuth_edges_[k], hi = azimuth_edges_[k + 1];
    cells_in_view_ += std::max(0.0, std::min(hi, h) - std::max(lo, -h)) / (hi - lo);
  }
}

std::uint64_t SensorModel::AzimuthCell(double azimuth) const {
  const auto it = std::upper_bound(azimuth_edges_.begin(), azimuth_edges_.end(), azimuth);
  const auto k = std::distance(azimuth_edges_.begin(), it) - 1;
  return static_cast<std::uint64_t>(std::clamp<std::ptrdiff_t>(k, 0, AzimuthCells() - 1));
}

double SensorModel::SnrDb(double rcs_dbsm, double range) const {
  return loop_gain_db_ + rcs_dbsm - 40.0 * std::log10(range);
}

double SensorModel::DetectionProbabilityAt(double snr_linear) const {
  return 0.5 * std::erfc(erfcinv_2pfa_ - std::sqrt(std::max(snr_linear, 0.0)));
}

double SensorModel::RangeSigma(double snr) const {
  const double d = params_.range_resolution, a = params_.range_accuracy;
  return std::sqrt(d * d * 12.0 / (8.0 * kPi * kPi * snr) + a * a);
}

double SensorModel::AzimuthSigma(double snr, double azimuth) const {
  const double d = params_.AzimuthResolutionAt(azimuth), a = params_.AzimuthAccuracyAt(azimuth);
  return std::sqrt(d * d / (1.6 * 1.6 * 2.0 * snr) + a * a);
}

double SensorModel::RangeRateSigma(double snr) const {
  const double d = params_.range_rate_resolution, a = params_.range_rate_accuracy;
  return std::sqrt(d * d * 6.0 / (4.0 * kPi * kPi * snr) + a * a);
}

double SensorModel::ResolutionCellCount() const {
  const SensorParams& p = params_;
  return (p.max_range - p.min_range) / p.range_resolution * AzimuthCellsInView() *
         ((p.max_range_rate - p.min_range_rate) / p.range_rate_resolution);
}

bool SensorModel::InWindow(const Polar& m) const {
  return m.range >= params_.min_range && m.range <= params_.max_range &&
         std::abs(m.azimuth) <= 0.5 * params_.fov && m.range_rate >= params_.min_range_rate &&
         m.range_rate <= params_.max_range_rate;
}

std::optional<Polar> SensorModel::Measure(const Polar& truth, double snr_linear, bool noise,
                                          CounterRng& rng) const {
  assert(snr_linear > 0.0);
  if (rng.Uniform() >= DetectionProbabilityAt(snr_linear)) return std::nullopt;
  Polar m = truth;
  if (noise) {
    m.range += RangeSigma(snr_linear) * rng.Normal();
    m.azimuth = WrapAngle(m.azimuth + AzimuthSigma(snr_linear, truth.azimuth) * rng.Normal());
    m.range_rate += RangeRateSigma(snr_linear) * rng.Normal();
  }
  if (!InWindow(m)) return std::nullopt;
  return m;
}

}  // namespace dualgrid::radar
