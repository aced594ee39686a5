// The Doppler fit's robust fit as it was defined before the fast median (issue 37): ordinary
// least squares, then six Tukey reweightings, the scale from a sorted copy's median
// (std::nth_element). test_doppler_fit.cpp holds filter/src/doppler_fit.cpp's
// detail::RobustDopplerFit to it, bit for bit.
#pragma once

#include <algorithm>
#include <cmath>

#include "dualgrid/filter/doppler_fit.hpp"

namespace dualgrid::filter_ref {

inline bool SolveFit(const double* ux, const double* uy, const double* y, const double* w, int n,
                     filter::detail::DopplerFit* f) {
  double a00 = 0.0, a01 = 0.0, a11 = 0.0, b0 = 0.0, b1 = 0.0;
  for (int i = 0; i < n; ++i) {
    a00 += w[i] * ux[i] * ux[i];
    a01 += w[i] * ux[i] * uy[i];
    a11 += w[i] * uy[i] * uy[i];
    b0 += w[i] * ux[i] * y[i];
    b1 += w[i] * uy[i] * y[i];
  }
  const double det = a00 * a11 - a01 * a01;
  if (!(det > 1e-12 * (a00 + a11) * (a00 + a11))) return false;
  f->vx = (a11 * b0 - a01 * b1) / det;
  f->vy = (a00 * b1 - a01 * b0) / det;
  f->a00 = a00;
  f->a01 = a01;
  f->a11 = a11;
  return true;
}

inline bool RobustFit(const double* ux, const double* uy, const double* y, int n, double floor,
                      filter::detail::DopplerFit* f) {
  constexpr int kMax = filter::detail::kFitMaxNeighbours;
  double w[kMax], r[kMax];
  std::fill_n(w, n, 1.0);
  if (!SolveFit(ux, uy, y, w, n, f)) return false;
  for (int it = 0; it < 6; ++it) {
    for (int i = 0; i < n; ++i) r[i] = std::abs(ux[i] * f->vx + uy[i] * f->vy - y[i]);
    double sorted[kMax];
    std::copy_n(r, n, sorted);
    std::nth_element(sorted, sorted + n / 2, sorted + n);
    f->scale = std::max(floor, 1.4826 * sorted[n / 2]);
    const double c = 4.685 * f->scale;
    f->inliers = 0;
    for (int i = 0; i < n; ++i) {
      const double q = r[i] / c;
      w[i] = q < 1.0 ? (1.0 - q * q) * (1.0 - q * q) : 0.0;
      f->inliers += q < 1.0;
    }
    if (f->inliers < 3 || !SolveFit(ux, uy, y, w, n, f)) return false;
  }
  return true;
}

}  // namespace dualgrid::filter_ref
