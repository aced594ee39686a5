// Between cycles (docs/algorithm.md, "Grid frame"): the caller's frame turns about its origin, so
// that a grid following the ego's heading stays along the road. Particles are turned exactly;
// cell masses, which live on the lattice, are resampled from the old lattice by nearest cell.
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "dualgrid/core/parallel.hpp"
#include "dualgrid/filter/dynamic_grid.hpp"
#include "grid_internal.hpp"
#include "team.hpp"

namespace dualgrid::filter {

using namespace detail;

void DynamicGrid::Reframe(double angle, const Position& ego) {
  if (!std::isfinite(angle) || !(ego.cwiseAbs().maxCoeff() <= FilterParams::kMaxCentre)) {
    throw std::invalid_argument(
        "DynamicGrid::Reframe: the angle must be finite and the ego position finite with |x|, "
        "|y| <= 1e9 m");
  }
  if (!initialized_ || angle == 0.0) return;
  sorted_current_ = false;  // the weighted particles stay binned on the old cells
  // New coordinates of a point with old coordinates p: R(-angle) p.
  const double c = std::cos(angle), s = std::sin(angle);
  const std::int64_t n = static_cast<std::int64_t>(particles_.size());
  LocalParticles& q = particles_;
  // Positions through the caller's frame in double: old local metres -> old caller coordinates
  // -> turned -> new local metres (the new origin, OriginFor(ego) below).
  const std::array<std::int64_t, 2> new_origin = OriginFor(ego);
  const double r = params_.resolution;
  const double ox = static_cast<double>(origin_gx_), oy = static_cast<double>(origin_gy_);
  const double nx0 = static_cast<double>(new_origin[0]), ny0 = static_cast<double>(new_origin[1]);
  const auto turn = [&](std::int64_t i) {
    const double x = ox * r + q.x[i], y = oy * r + q.y[i], vx = q.vx[i], vy = q.vy[i];
    q.x[i] = static_cast<float>((c * x + s * y) - nx0 * r);
    q.y[i] = static_cast<float>((-s * x + c * y) - ny0 * r);
    q.vx[i] = static_cast<float>(c * vx + s * vy);
    q.vy[i] = static_cast<float>(-s * vx + c * vy);
  };
  InvalidateExports();

  // The old layers, then each new cell from the old cell under its centre.
  const std::size_t cells = static_cast<std::size_t>(num_cells_);
  reframe_layers_.resize(3 * cells);  // before the region: nothing in it may throw
  const auto keep_old = [&] {
    std::copy(free_.begin(), free_.end(), reframe_layers_.begin());
    std::copy(static_.begin(), static_.end(), reframe_layers_.begin() + cells);
    std::copy(dynamic_.begin(), dynamic_.end(), reframe_layers_.begin() + 2 * cells);
  };
  const double* const old_free = reframe_layers_.data();
  const double* const old_static = old_free + cells;
  const double* const old_dynamic = old_static + cells;
  const std::int64_t ogx = origin_gx_, ogy = origin_gy_;
  const std::int64_t gx = new_origin[0], gy = new_origin[1];
  const auto row = [&](std::int64_t iy) {
    const double yn = (static_cast<double>(gy + iy) + 0.5) * r;
    for (std::int64_t ix = 0; ix < nx_; ++ix) {
      const double xn = (static_cast<double>(gx + ix) + 0.5) * r;
      // The centre's old coordinates: R(angle) p.
      const double xo = c * xn - s * yn, yo = s * xn + c * yn;
      const std::int64_t ox = static_cast<std::int64_t>(std::floor(xo / r)) - ogx;
      const std::int64_t oy = static_cast<std::int64_t>(std::floor(yo / r)) - ogy;
      const std::int64_t to = Storage(gx + ix, gy + iy);
      if (ox < 0 || oy < 0 || ox >= nx_ || oy >= ny_) {
        free_[to] = static_[to] = dynamic_[to] = 0.0;  // unknown
        continue;
      }
      const std::int64_t from = Storage(ogx + ox, ogy + oy);
      free_[to] = old_free[from];
      static_[to] = old_static[from];
      dynamic_[to] = old_dynamic[from];
    }
  };
  // One region (none for one thread, as the cycle: team.hpp): the old layers are kept beside the
  // particles' turn, the rows are resampled after both.
  const auto run = [&](const Team& t) {
    SingleNoWait(t, keep_old);
    ForStatic(t, n, turn);
    ForStatic(t, ny_, row);
  };
  if (OneThreadHere()) {
    run(Team::Solo());
  } else {
#pragma omp parallel
    run(Team::OfRegion());
  }
  origin_gx_ = gx;
  origin_gy_ = gy;
}

}  // namespace dualgrid::filter
