// The measurement grid's bearing (step 4, the field of view and the ray free space's bins):
// internal to the filter (filter/src/measurement_grid.cpp); public so that tests/filter can hold
// its SIMD lanes to the scalar definition, bit for bit.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

namespace dualgrid::filter::detail {

/// FastAtan2's polynomial in the octant: ~atan(a) [rad] for a in [0, 1], increasing there (slope
/// 0.49 - 1).
/// Its coefficients: a - kAtanC1 a^3 + kAtanC2 a^5 - kAtanC3 a^7.
inline constexpr double kAtanC1 = 0.327622764, kAtanC2 = 0.15931422, kAtanC3 = 0.0464964749;
inline double FastAtanOctant(double a) {
  const double s = a * a;
  return ((-kAtanC3 * s + kAtanC2) * s - kAtanC1) * s * a + a;
}

/// atan2(y, x) [rad] by a polynomial in the octant, within 2.1e-4 rad of std::atan2 (5e-4
/// assumed); 0 at the origin. Inline: std::atan2 per cell and sensor dominated the free-space pass.
/// As a function of the direction (exact arithmetic) it increases over (-pi, pi], with upward
/// jumps of 4.1e-4 rad at the octant bounds +-pi/4, +-3pi/4 (the measurement grid relies on it).
inline double FastAtan2(double y, double x) {
  constexpr double kPi = std::numbers::pi;
  const double ax = std::abs(x), ay = std::abs(y);
  const double mx = std::max(ax, ay), mn = std::min(ax, ay);
  if (mx == 0.0) return 0.0;
  const double a = mn / mx;
  double r = FastAtanOctant(a);
  if (ay > ax) r = 0.5 * kPi - r;
  if (x < 0.0) r = kPi - r;
  return y < 0.0 ? -r : r;
}

/// out[i] = FastAtan2(y[i], x[i]) for i in [0, n), on the filter's SIMD lanes (the scalar
/// operations lane by lane): the same bits.
void FastAtan2Lanes(const double* y, const double* x, int n, double* out);

}  // namespace dualgrid::filter::detail
