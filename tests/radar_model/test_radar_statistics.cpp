// Statistical tests with fixed seeds. Tolerances are 5 standard errors derived from the model
// and the sample size (false-failure probability below 1e-6 per check), never tuned.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "dualgrid/radar_model/radar_model.hpp"

using namespace dualgrid;
using namespace dualgrid::radar;

namespace {

double DbToLinear(double db) { return std::pow(10.0, 0.1 * db); }

struct Moments {
  int n = 0;
  double sum = 0.0, sum2 = 0.0;
  void Add(double x) {
    ++n;
    sum += x;
    sum2 += x * x;
  }
  double Mean() const { return sum / n; }
  double Std() const { return std::sqrt((sum2 - sum * sum / n) / (n - 1)); }
};

// Standard error of a normal sample's standard deviation: sigma / sqrt(2 (n - 1)).
bool StdMatches(const Moments& m, double sigma) {
  return std::abs(m.Std() - sigma) < 5.0 * sigma / std::sqrt(2.0 * (m.n - 1));
}

}  // namespace

TEST_CASE("ErfcInv inverts erfc", "[radar][math]") {
  const double y = GENERATE(1e-12, 2e-6, 1e-3, 0.1, 0.5, 0.999, 1.0, 1.3, 1.8, 1.999999);
  const double x = ErfcInv(y);
  CHECK(std::erfc(x) == Approx(y).epsilon(1e-12));
  CHECK_THROWS(ErfcInv(0.0));
  CHECK_THROWS(ErfcInv(2.0));
}

TEST_CASE("Loop gain puts the reference target at the reference Pd", "[radar][math]") {
  std::vector<SensorParams> sensors = DefaultRig(4.5, 1.8);
  SensorParams custom = DefaultShortRangeRadar();
  custom.reference_range = 35.0;
  custom.reference_rcs_dbsm = -3.0;
  custom.reference_pd = 0.5;
  custom.false_alarm_rate = 1e-4;
  sensors.push_back(custom);
  for (const SensorParams& p : sensors) {
    const SensorModel model(p);
    const double snr_db = model.SnrDb(p.reference_rcs_dbsm, p.reference_range);
    CHECK(model.DetectionProbabilityAt(DbToLinear(snr_db)) == Approx(p.reference_pd));
    CHECK(DetectionProbability(DbToLinear(snr_db), p.false_alarm_rate) == Approx(p.reference_pd));
    // Radar equation: 40 log10(2) dB less at twice the range, +10 dB for +10 dBsm.
    CHECK(model.SnrDb(p.reference_rcs_dbsm, 2.0 * p.reference_range) ==
          Approx(snr_db - 40.0 * std::log10(2.0)));
    CHECK(model.SnrDb(p.reference_rcs_dbsm + 10.0, p.reference_range) == Approx(snr_db + 10.0));
    CHECK(10.0 * std::log10(model.SnrLinear(DbToLinear(p.reference_rcs_dbsm), p.reference_range)) ==
          Approx(snr_db));
  }
}

TEST_CASE("Measurement noise matches the resolution/SNR formulas", "[radar][statistics]") {
  const double snr_db = GENERATE(12.0, 18.0, 30.0);
  const SensorParams p = GENERATE(DefaultShortRangeRadar(), DefaultLongRangeRadar());
  const SensorModel model(p);
  const double snr = DbToLinear(snr_db);
  // Far from the window edges, so no noisy sample is cut off.
  const Polar truth{0.5 * (p.min_range + p.max_range), 0.0, 0.0};
  Moments range, azimuth, range_rate;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    CounterRng rng(11, RngPurpose::kTest, static_cast<std::uint64_t>(snr_db), i);
    const std::optional<Polar> m = model.Measure(truth, snr, true, rng);
    if (!m) continue;
    range.Add(m->range - truth.range);
    azimuth.Add(m->azimuth - truth.azimuth);
    range_rate.Add(m->range_rate - truth.range_rate);
  }
  REQUIRE(range.n > 1000);
  // At boresight (truth.azimuth = 0 here) the profile factors are 1.
  const double sr = std::sqrt(std::pow(p.range_resolution, 2) * 12.0 / (8.0 * kPi * kPi * snr) +
                              std::pow(p.range_accuracy, 2));
  const double sa = std::sqrt(std::pow(p.azimuth_resolution, 2) / (1.6 * 1.6 * 2.0 * snr) +
                              std::pow(p.azimuth_accuracy, 2));
  const double srr =
      std::sqrt(std::pow(p.range_rate_resolution, 2) * 6.0 / (4.0 * kPi * kPi * snr) +
                std::pow(p.range_rate_accuracy, 2));
  CHECK(model.RangeSigma(snr) == Approx(sr));
  CHECK(model.AzimuthSigma(snr) == Approx(sa));
  CHECK(model.RangeRateSigma(snr) == Approx(srr));
  CHECK(StdMatches(range, sr));
  CHECK(StdMatches(azimuth, sa));
  CHECK(StdMatches(range_rate, srr));
  // Unbiased: mean within 5 standard errors sigma / sqrt(n).
  CHECK(std::abs(range.Mean()) < 5.0 * sr / std::sqrt(range.n));
  CHECK(std::abs(azimuth.Mean()) < 5.0 * sa / std::sqrt(azimuth.n));
  CHECK(std::abs(range_rate.Mean()) < 5.0 * srr / std::sqrt(range_rate.n));
}

TEST_CASE("Detection rate matches the ROC within a binomial interval", "[radar][statistics]") {
  const double snr_db = GENERATE(9.0, 11.0, 12.6, 14.0);
  const double pfa = GENERATE(1e-6, 1e-4);
  SensorParams p = DefaultShortRangeRadar();
  p.false_alarm_rate = pfa;
  const SensorModel model(p);
  const double snr = DbToLinear(snr_db);
  const double pd = 0.5 * std::erfc(ErfcInv(2.0 * pfa) - std::sqrt(snr));
  const int n = 20000;
  int detected = 0;
  for (int i = 0; i < n; ++i) {
    CounterRng rng(5, RngPurpose::kTest, 1000 + static_cast<int>(10 * snr_db), i);
    detected += model.Measure(Polar{40.0, 0.0, 0.0}, snr, false, rng).has_value();
  }
  CHECK(std::abs(static_cast<double>(detected) / n - pd) < 5.0 * std::sqrt(pd * (1 - pd) / n));
}

// End to end through Scan: a 5 cm box whose scatterers all fall into one resolution cell, so the
// cell SNR is the box's RCS through the radar equation (its extent changes R^4 by < 0.5 %).
TEST_CASE("A point-like target is detected at the ROC rate with the formula noise",
          "[radar][statistics]") {
  const double snr_db = GENERATE(11.0, 16.0);
  SensorParams p = DefaultShortRangeRadar();
  const SensorModel sensor(p);
  // Centre of a range cell and of an azimuth cell, static target seen from a static sensor.
  const double range = (std::floor(40.0 / p.range_resolution) + 0.5) * p.range_resolution;
  // The first azimuth cell right of the boresight: [0, resolution at its middle).
  const double az = 0.5 * p.AzimuthResolutionAt(0.5 * p.azimuth_resolution);
  const double rcs_dbsm = snr_db - sensor.SnrDb(0.0, range);
  Scene scene;
  scene.targets.push_back(
      {7, OrientedBox{range * UnitVector(az), 0.3, 0.05, 0.05}, Velocity::Zero(), 0.0, rcs_dbsm});
  const RadarModel model({p}, ModelOptions{true, false, true, {}}, 2024);
  const EgoMotion ego{};
  const double snr = DbToLinear(snr_db);
  const int n = 4000;
  int detected = 0;
  Moments dr, da, drr;
  for (int step = 0; step < n; ++step) {
    const std::vector<Detection> dets = model.ScanSensor(0, ego, scene, step);
    REQUIRE(dets.size() <= 1);
    if (dets.empty()) continue;
    ++detected;
    CHECK(dets[0].source_id == 7);
    CHECK(dets[0].snr_db == Approx(snr_db).margin(0.03));
    dr.Add(dets[0].range - range);
    da.Add(dets[0].azimuth - az);
    drr.Add(dets[0].range_rate);
  }
  // Bounds of Pd over the +-0.5 % SNR uncertainty, widened by 5 binomial standard errors.
  const auto roc = [&](double x) {
    return 0.5 * std::erfc(ErfcInv(2.0 * p.false_alarm_rate) - std::sqrt(x));
  };
  const double pd_lo = roc(0.995 * snr), pd_hi = roc(1.005 * snr);
  const double rate = static_cast<double>(detected) / n;
  CHECK(rate > pd_lo - 5.0 * std::sqrt(pd_lo * (1 - pd_lo) / n));
  CHECK(rate < pd_hi + 5.0 * std::sqrt(pd_hi * (1 - pd_hi) / n));
  // The noise-free cell position is the same every scan, so the target's extent shifts the
  // mean only; the +-0.5 % SNR uncertainty moves sigma by < 0.3 %, far below the tolerance.
  CHECK(StdMatches(dr, sensor.RangeSigma(snr)));
  CHECK(StdMatches(da, sensor.AzimuthSigma(snr)));
  CHECK(StdMatches(drr, sensor.RangeRateSigma(snr)));
}

TEST_CASE("False-alarm count matches cells times rate", "[radar][statistics]") {
  const SensorParams p = GENERATE(DefaultShortRangeRadar(), DefaultLongRangeRadar());
  const double pfa = GENERATE(1e-6, 3e-6);
  SensorParams q = p;
  q.false_alarm_rate = pfa;
  const SensorModel sensor(q);
  // Azimuth cells in view: the integral of 1 / resolution(az) over the field of view (the
  // midpoint rule of the cell edges agrees to < 1 %), fov / resolution without a profile.
  double azimuth_cells = 0.0;
  const int steps = 100000;
  for (int i = 0; i < steps; ++i) {
    const double az = -0.5 * q.fov + (i + 0.5) * q.fov / steps;
    azimuth_cells += q.fov / steps / q.AzimuthResolutionAt(az);
  }
  if (q.off_boresight.empty()) CHECK(azimuth_cells == Approx(q.fov / q.azimuth_resolution));
  CHECK(sensor.AzimuthCellsInView() == Approx(azimuth_cells).epsilon(0.01));
  const double cells = (q.max_range - q.min_range) / q.range_resolution *
                       sensor.AzimuthCellsInView() *
                       ((q.max_range_rate - q.min_range_rate) / q.range_rate_resolution);
  CHECK(sensor.ResolutionCellCount() == Approx(cells));
  const double lambda = cells * pfa;
  const RadarModel model({q}, ModelOptions{true, true, true, {}}, 99);
  const int scans = 3000;
  Moments count, range;
  for (int step = 0; step < scans; ++step) {
    const std::vector<Detection> dets = model.ScanSensor(0, EgoMotion{}, Scene{}, step);
    count.Add(static_cast<double>(dets.size()));
    for (const Detection& d : dets) {
      REQUIRE(d.is_clutter);
      REQUIRE(d.source_id == -1);
      REQUIRE(sensor.InWindow(Polar{d.range, d.azimuth, d.range_rate}));
      range.Add(d.range);
    }
  }
  // Poisson: standard error sqrt(lambda / scans).
  CHECK(std::abs(count.Mean() - lambda) < 5.0 * std::sqrt(lambda / scans));
  // Uniform in range: mean (min+max)/2, standard error (max-min)/sqrt(12 n).
  CHECK(std::abs(range.Mean() - 0.5 * (q.min_range + q.max_range)) <
        5.0 * (q.max_range - q.min_range) / std::sqrt(12.0 * range.n));
  // Switched off: none.
  const RadarModel quiet({q}, ModelOptions{true, false, true, {}}, 99);
  CHECK(quiet.ScanSensor(0, EgoMotion{}, Scene{}, 1).empty());
}

TEST_CASE("Azimuth resolution and accuracy follow the data-sheet profile off boresight",
          "[radar][statistics]") {
  // ARS408-21 near range: resolution 3.2 / 4.5 / 12.3 deg, accuracy 0.3 / 1 / 5 deg at
  // 0 / 45 / 60 deg; linear in between, constant beyond 60 deg, symmetric.
  const SensorParams p = DefaultShortRangeRadar();
  const auto deg = [](double d) { return DegToRad(d); };
  CHECK(p.AzimuthResolutionAt(0.0) == Approx(deg(3.2)));
  CHECK(p.AzimuthResolutionAt(deg(45)) == Approx(deg(4.5)));
  CHECK(p.AzimuthResolutionAt(deg(-60)) == Approx(deg(12.3)));
  CHECK(p.AzimuthResolutionAt(deg(75)) == Approx(deg(12.3)));
  CHECK(p.AzimuthResolutionAt(deg(30)) == Approx(deg(3.2 + 30.0 / 45.0 * 1.3)));
  CHECK(p.AzimuthAccuracyAt(deg(45)) == Approx(deg(1.0)));
  CHECK(p.AzimuthAccuracyAt(deg(60)) == Approx(deg(5.0)));
  CHECK(p.AzimuthAccuracyAt(deg(-52.5)) == Approx(deg(3.0)));
  // Measured noise follows it: 20,000 noisy azimuths at high SNR at 52.5 deg off boresight.
  const SensorModel model(p);
  const double snr = DbToLinear(40.0);
  const Polar truth{40.0, deg(52.5), 0.0};
  Moments azimuth;
  for (int i = 0; i < 20000; ++i) {
    CounterRng rng(5, RngPurpose::kTest, 52, i);
    if (const std::optional<Polar> m = model.Measure(truth, snr, true, rng))
      azimuth.Add(m->azimuth - truth.azimuth);
  }
  CHECK(StdMatches(azimuth, model.AzimuthSigma(snr, truth.azimuth)));
  CHECK(model.AzimuthSigma(snr, truth.azimuth) > 2.5 * model.AzimuthSigma(snr, 0.0));
  // Cells widen with the resolution: fewer cells per degree off boresight.
  const auto cell = [&](double d) { return static_cast<double>(model.AzimuthCell(deg(d))); };
  CHECK(cell(3.3) - cell(0.1) == 1.0);
  CHECK(cell(70.0) - cell(55.0) <= 2.0);
  CHECK(model.AzimuthCell(deg(-0.1)) + 1 == model.AzimuthCell(deg(0.1)));
  // The clean setting: no profile, MATLAB's bias fractions as floors.
  const SensorParams clean = DefaultShortRangeRadar(Accuracy::kClean);
  CHECK(clean.AzimuthResolutionAt(deg(60)) == Approx(clean.azimuth_resolution));
  CHECK(clean.range_rate_accuracy == Approx(0.05 * clean.range_rate_resolution));
}
