#include "dualgrid/radar_model/sensor_params.hpp"

#include <cmath>
#include <stdexcept>

#include "dualgrid/core/text.hpp"
#include "dualgrid/core/validation.hpp"

namespace dualgrid::radar {
namespace {

// Resolution-cell indices are packed 20 bits per dimension (radar_model.cpp).
constexpr double kMaxBins = 1 << 20;

// Farthest a sensor may sit from the ego's box centre [m], along x and along y: on the car.
constexpr double kMaxMountOffset = 50.0;

// Longest sensor name [bytes]: names are CSV fields, folder-free labels and figure legends.
constexpr std::size_t kMaxNameBytes = 64;

// A name that every CSV we write holds as one unquoted field: printable (UTF-8 allowed), no
// comma, no double quote, no control character (newline, tab, NUL, DEL).
bool IsPlainName(const std::string& name) {
  if (name.empty() || name.size() > kMaxNameBytes) return false;
  for (const char ch : name) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x20 || c == 0x7f || c == ',' || c == '"') return false;
  }
  return true;
}

// `name` as a message can show it on one line: control characters as '?', at most 80 bytes.
std::string Shown(const std::string& name) {
  std::string out = "'";
  for (const char ch : name.substr(0, 80)) {
    const auto c = static_cast<unsigned char>(ch);
    out += c < 0x20 || c == 0x7f ? '?' : ch;
  }
  return out + (name.size() > 80 ? "...'" : "'");
}

}  // namespace

bool SensorParams::IsValid(std::string* error) const {
  using std::isfinite;
  FieldCheck c;
  c.Expect(IsPlainName(name), "name", Shown(name),
           "a name of 1 to 64 bytes without comma, double quote or control characters (it is a "
           "CSV field)");
  c.Expect(mount.position.allFinite() && isfinite(mount.yaw) &&
               mount.position.cwiseAbs().maxCoeff() <= kMaxMountOffset &&
               std::abs(mount.yaw) <= 2.0 * kPi,
           "mount", FormatTuple({mount.position.x(), mount.position.y(), mount.yaw}),
           "x, y within +-50 m of the ego's centre, yaw within +-2 pi rad");
  c.Expect(fov > 0.0 && fov <= 2.0 * kPi, "fov", fov,
           "in (0, 2 pi] rad (the full azimuth field of view)");
  c.NonNegative("min_range", min_range, "m");
  c.Expect(isfinite(max_range) && max_range > min_range, "max_range", max_range,
           "finite and > min_range = " + FormatShort(min_range) + " m");
  c.Finite("min_range_rate", min_range_rate, "m/s");
  c.Expect(isfinite(max_range_rate) && max_range_rate > min_range_rate, "max_range_rate",
           max_range_rate, "finite and > min_range_rate = " + FormatShort(min_range_rate) + " m/s");
  c.Expect(isfinite(range_resolution) && range_resolution > 0.0 &&
               max_range / range_resolution < kMaxBins,
           "range_resolution", range_resolution,
           "> 0 m with fewer than 2^20 range cells up to max_range");
  c.Expect(isfinite(azimuth_resolution) && azimuth_resolution > 0.0 &&
               fov / azimuth_resolution < kMaxBins - 4,  // + the partial cells at the edges
           "azimuth_resolution", azimuth_resolution,
           "> 0 rad with fewer than 2^20 azimuth cells over the fov");
  c.Expect(isfinite(range_rate_resolution) && range_rate_resolution > 0.0 &&
               (max_range_rate - min_range_rate) / range_rate_resolution < kMaxBins,
           "range_rate_resolution", range_rate_resolution,
           "> 0 m/s with fewer than 2^20 range-rate cells over the range-rate window");
  c.NonNegative("range_accuracy", range_accuracy, "m");
  c.NonNegative("azimuth_accuracy", azimuth_accuracy, "rad");
  c.NonNegative("range_rate_accuracy", range_rate_accuracy, "m/s");
  c.Expect(off_boresight_resolution.size() == off_boresight.size() &&
               off_boresight_accuracy.size() == off_boresight.size(),
           "off_boresight",
           std::to_string(off_boresight.size()) + " angles, " +
               std::to_string(off_boresight_resolution.size()) + " resolution and " +
               std::to_string(off_boresight_accuracy.size()) + " accuracy factors",
           "off_boresight_deg, off_boresight_resolution and off_boresight_accuracy of the same "
           "length");
  for (std::size_t k = 0; c.ok() && k < off_boresight.size(); ++k) {
    const double a = off_boresight[k];
    if (k == 0)
      c.Expect(a >= 0.0 && a <= kPi, Indexed("off_boresight", k), a, "in [0, pi] rad");
    else
      c.Expect(a > off_boresight[k - 1] && a <= kPi, Indexed("off_boresight", k), a,
               "in (" + Indexed("off_boresight", k - 1) + " = " +
                   FormatShort(off_boresight[k - 1]) + ", pi] rad (increasing)");
    c.InRange(Indexed("off_boresight_resolution", k), off_boresight_resolution[k], 1.0, 100.0);
    c.InRange(Indexed("off_boresight_accuracy", k), off_boresight_accuracy[k], 1.0, 1000.0);
  }
  c.Positive("reference_range", reference_range, "m");
  // 10^(rcs / 10) must stay finite (1e300 dBsm gave NaN weights); the scenario bounds too.
  c.InRange("reference_rcs_dbsm", reference_rcs_dbsm, -60.0, 80.0, Interval::kClosed, "dBsm");
  c.InRange("false_alarm_rate", false_alarm_rate, 0.0, 0.5, Interval::kOpen);
  c.Expect(reference_pd > false_alarm_rate && reference_pd < 1.0, "reference_pd", reference_pd,
           "in (false_alarm_rate = " + FormatShort(false_alarm_rate) + ", 1)");
  c.Positive("update_period", update_period, "s");
  return c.Done(error);
}

namespace {

// Piecewise-linear factor of the off-boresight profile at |az|: 1 before the first point,
// constant beyond the last.
double ProfileFactor(const std::vector<double>& at, const std::vector<double>& factor, double az) {
  const double a = std::abs(az);
  if (at.empty() || a < at.front()) return 1.0;
  for (std::size_t k = 1; k < at.size(); ++k) {
    if (a <= at[k]) {
      const double t = (a - at[k - 1]) / (at[k] - at[k - 1]);
      return factor[k - 1] + t * (factor[k] - factor[k - 1]);
    }
  }
  return factor.back();
}

void MakeClean(SensorParams* p) {
  p->range_accuracy = 0.05 * p->range_resolution;
  p->azimuth_accuracy = 0.1 * p->azimuth_resolution;
  p->range_rate_accuracy = 0.05 * p->range_rate_resolution;
  p->off_boresight.clear();
  p->off_boresight_resolution.clear();
  p->off_boresight_accuracy.clear();
}

}  // namespace

double SensorParams::AzimuthResolutionAt(double az) const {
  return azimuth_resolution * ProfileFactor(off_boresight, off_boresight_resolution, az);
}

double SensorParams::AzimuthAccuracyAt(double az) const {
  return azimuth_accuracy * ProfileFactor(off_boresight, off_boresight_accuracy, az);
}

SensorParams DefaultShortRangeRadar(Accuracy accuracy) {
  SensorParams p;  // the struct defaults are the corner radar (sources in docs/radar.md)
  p.name = "short_range";
  if (accuracy == Accuracy::kClean) MakeClean(&p);
  return p;
}

SensorParams DefaultLongRangeRadar(Accuracy accuracy) {
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
  // Accuracy: ARS408-21 far range (distance +-0.40 m, azimuth +-0.1 deg within its +-9 deg: no
  // off-boresight profile over the 20 deg field of view); range rate: Delphi ESR +-0.12 m/s.
  p.range_accuracy = 0.40;
  p.azimuth_accuracy = DegToRad(0.1);
  p.range_rate_accuracy = 0.12;
  p.off_boresight.clear();
  p.off_boresight_resolution.clear();
  p.off_boresight_accuracy.clear();
  if (accuracy == Accuracy::kClean) MakeClean(&p);
  return p;
}

std::vector<SensorParams> DefaultRig(double ego_length, double ego_width, Accuracy accuracy) {
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
    SensorParams p = DefaultShortRangeRadar(accuracy);
    p.name = c.name;
    p.mount = Pose2{Position(c.x, c.y), DegToRad(c.yaw_deg)};
    rig.push_back(p);
  }
  SensorParams front = DefaultLongRangeRadar(accuracy);
  front.name = "front";
  front.mount = Pose2{Position(0.5 * ego_length, 0.0), 0.0};
  rig.push_back(front);
  return rig;
}

}  // namespace dualgrid::radar
