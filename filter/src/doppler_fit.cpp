// Step 4a (birth_velocity: doppler_fit, velocity_likelihood: radial_fit; docs/algorithm.md
// "Births"): a detection's Doppler gives one component of its object's velocity, along its line of
// sight. The detections of one object see it along different lines of sight (other points of its
// outline, other sensors), so together they fix the whole velocity vector where those lines spread
// enough: v with u_i . v = v_r,i for every detection i near it. Fitted robustly (Tukey's biweight
// by iteratively reweighted least squares), since detections of another object, of the ground or
// clutter may lie within reach.
#include <algorithm>
#include <cmath>
#include <limits>

#include "dualgrid/filter/measurement_grid.hpp"
#include "grid_internal.hpp"
#include "team.hpp"

namespace dualgrid::filter {

using namespace detail;

namespace {

constexpr int kMaxNeighbours = 64;  // nearest-first is not needed: the first 64 in bucket order
// Candidates looked at per detection at most (docs/algorithm.md, step 4a): bounds a fit's cost
// when thousands of detections crowd its buckets, so that a cycle's cost stays linear in them.
constexpr int kMaxCandidates = 8 * kMaxNeighbours;
constexpr int kIterations = 6;
constexpr double kTukey = 4.685;  // 95 % efficiency at Gaussian noise
constexpr double kMadToSigma = 1.4826;

struct Fit {
  double vx = 0.0, vy = 0.0, scale = 0.0;
  double a00 = 0.0, a01 = 0.0, a11 = 0.0;  // sum of w u u^T at the solution
  int inliers = 0;
};

// Solves sum_i w_i u_i u_i^T v = sum_i w_i u_i y_i; false when the lines of sight (weighted) do
// not span the plane.
bool Solve(const double* ux, const double* uy, const double* y, const double* w, int n, Fit* f) {
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

// Tukey-weighted fit starting from ordinary least squares; the scale is the residuals' MAD, at
// least `floor` (the radars' noise).
bool RobustFit(const double* ux, const double* uy, const double* y, int n, double floor, Fit* f) {
  double w[kMaxNeighbours], r[kMaxNeighbours];
  std::fill_n(w, n, 1.0);
  if (!Solve(ux, uy, y, w, n, f)) return false;
  for (int it = 0; it < kIterations; ++it) {
    for (int i = 0; i < n; ++i) r[i] = std::abs(ux[i] * f->vx + uy[i] * f->vy - y[i]);
    double sorted[kMaxNeighbours];
    std::copy_n(r, n, sorted);
    std::nth_element(sorted, sorted + n / 2, sorted + n);
    f->scale = std::max(floor, kMadToSigma * sorted[n / 2]);
    const double c = kTukey * f->scale;
    f->inliers = 0;
    for (int i = 0; i < n; ++i) {
      const double q = r[i] / c;
      w[i] = q < 1.0 ? (1.0 - q * q) * (1.0 - q * q) : 0.0;
      f->inliers += q < 1.0;
    }
    if (f->inliers < 3 || !Solve(ux, uy, y, w, n, f)) return false;
  }
  return true;
}

}  // namespace

double MeasurementGrid::BucketDistance2(const Position& p, int bx, int by) const {
  const double edge = 1.0 / bucket_inv_;
  const double x0 = static_cast<double>(origin_gx_) * params_.resolution + bx * edge;
  const double y0 = static_cast<double>(origin_gy_) * params_.resolution + by * edge;
  const double lo_x = bx == 0 ? -kInf : x0, hi_x = bx == nbx_ - 1 ? kInf : x0 + edge;
  const double lo_y = by == 0 ? -kInf : y0, hi_y = by == nby_ - 1 ? kInf : y0 + edge;
  const double dx = std::max({lo_x - p.x(), 0.0, p.x() - hi_x});
  const double dy = std::max({lo_y - p.y(), 0.0, p.y() - hi_y});
  return dx * dx + dy * dy;
}

void MeasurementGrid::FitDetectionVelocities(const Team& t) {
  const std::span<const Measurement> z = z_;
  const int nz = static_cast<int>(z.size());  // det_fit_t_, det_fit_sd_: Prepare sized them
  const double radius2 = params_.doppler_fit_radius * params_.doppler_fit_radius;
  const int reach = static_cast<int>(
      std::ceil(params_.doppler_fit_radius / (bucket_cells_ * params_.resolution)));
  const double floor = params_.doppler_fit_sigma;
  const double* const los = det_los_.data();  // ComputeLinesOfSight, this cycle
  const auto fit = [&](std::int64_t jj) {
    const int j = static_cast<int>(jj);
    det_fit_t_[j] = 0.0;
    det_fit_sd_[j] = std::numeric_limits<double>::infinity();
    if (det_bucket_[j] < 0) return;  // not near the grid: no birth from it
    const Position& p = z[j].position;
    const auto [bx, by] = BucketOf(p.x(), p.y());
    double ux[kMaxNeighbours], uy[kMaxNeighbours], y[kMaxNeighbours];
    int n = 0, looked = 0;
    for (int cy = std::max(0, by - reach); cy <= std::min(nby_ - 1, by + reach); ++cy) {
      for (int cx = std::max(0, bx - reach); cx <= std::min(nbx_ - 1, bx + reach); ++cx) {
        // No neighbour can lie there (a relative margin for the rounding of BucketOf's edges).
        if (BucketDistance2(p, cx, cy) > radius2 * (1.0 + 1e-9)) continue;
        const std::int64_t b = static_cast<std::int64_t>(cy) * nbx_ + cx;
        for (std::int64_t k = bucket_start_[b];
             k < bucket_start_[b + 1] && n < kMaxNeighbours && looked < kMaxCandidates;
             ++k, ++looked) {
          // det_x_/det_y_: the positions in bucket order (contiguous, unlike z[i]).
          const double ex = det_x_[k] - p.x(), ey = det_y_[k] - p.y();
          if (ex * ex + ey * ey > radius2) continue;
          const int i = bucket_items_[k];
          ux[n] = los[3 * i];
          uy[n] = los[3 * i + 1];
          y[n] = los[3 * i + 2];
          ++n;
        }
      }
    }
    Fit f;
    if (n < 3 || !RobustFit(ux, uy, y, n, floor, &f)) return;
    // The velocity's part along this detection's tangent (-u_y, u_x), and its variance
    // t^T (scale^2 A^-1) t.
    const double tx = -los[3 * j + 1], ty = los[3 * j];
    const double det = f.a00 * f.a11 - f.a01 * f.a01;
    const double var =
        f.scale * f.scale * (tx * tx * f.a11 - 2.0 * tx * ty * f.a01 + ty * ty * f.a00) / det;
    det_fit_t_[j] = f.vx * tx + f.vy * ty;
    det_fit_sd_[j] = std::sqrt(std::max(0.0, var));
  };
  ForDynamicNoWait(t, nz, fit, 32);  // Fill's contract: no barrier at the end
}

}  // namespace dualgrid::filter
