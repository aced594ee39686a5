// The Doppler fit's robust fit as it was defined before the fast median (issue 37): ordinary
// least squares, then six Tukey reweightings, the scale from a sorted copy's median
// (std::nth_element). test_doppler_fit.cpp holds filter/src/doppler_fit.cpp's
// detail::RobustDopplerFit to it, bit for bit.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

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

// The fit's gathering as it was before the runs of buckets (issue 37, c65417c): bucket by bucket
// in each row, every point of a bucket not wholly beyond the radius looked at, the first
// kFitMaxNeighbours within the radius kept among the first kMaxCandidates looked at.
inline double BucketGapRef(double p, int b, int nb, double origin, double inv) {
  const double edge = 1.0 / inv;
  const double lo = origin + b * edge;
  const double inf = std::numeric_limits<double>::infinity();
  return std::max({(b == 0 ? -inf : lo) - p, 0.0, p - (b == nb - 1 ? inf : lo + edge)});
}

inline int GatherRef(const filter::detail::BucketView& v, double px, double py, int bx, int by,
                     int reach, double radius2, int* key) {
  const int cx_lo = std::max(0, bx - reach), cx_hi = std::min(v.nbx - 1, bx + reach);
  const int cy_lo = std::max(0, by - reach), cy_hi = std::min(v.nby - 1, by + reach);
  int n = 0, looked = 0;
  for (int cy = cy_lo; cy <= cy_hi; ++cy) {
    for (int cx = cx_lo; cx <= cx_hi; ++cx) {
      const double gx = BucketGapRef(px, cx, v.nbx, v.ox, v.inv);
      const double gy = BucketGapRef(py, cy, v.nby, v.oy, v.inv);
      if (gx * gx + gy * gy > radius2 * (1.0 + 1e-9)) continue;
      const std::int64_t b = static_cast<std::int64_t>(cy) * v.nbx + cx;
      for (std::int64_t k = v.start[b]; k < v.start[b + 1]; ++k, ++looked) {
        if (n == filter::detail::kFitMaxNeighbours || looked == filter::detail::kMaxCandidates)
          return n;
        const double ex = v.x[k] - px, ey = v.y[k] - py;
        if (!(ex * ex + ey * ey > radius2)) key[n++] = static_cast<int>(k);
      }
    }
  }
  return n;
}

}  // namespace dualgrid::filter_ref
