// Step 9 of the cycle (docs/algorithm.md, paper Sec. V): per-cell read-out of the masses and of the
// weighted velocity mean and covariance of a cell's particles, on demand (not part of Update).
#include "dualgrid/filter/dynamic_grid.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "grid_internal.hpp"

namespace dualgrid::filter {

using namespace detail;

namespace {

// The weighted mean velocity of particles [lo, hi) of `p` into `mean` (left unchanged when their
// weights sum to 0); returns the weight sum. Cell and ExportMeanVelocities share it.
double MeanVelocity(const LocalParticles& p, std::int64_t lo, std::int64_t hi, Velocity& mean) {
  double wsum = 0.0, mx = 0.0, my = 0.0;
  for (std::int64_t i = lo; i < hi; ++i) {
    wsum += p.weight[i];
    mx += p.weight[i] * static_cast<double>(p.vx[i]);
    my += p.weight[i] * static_cast<double>(p.vy[i]);
  }
  if (wsum > 0.0) mean = {mx / wsum, my / wsum};
  return wsum;
}

}  // namespace

// f(i, s, count) for the contiguous storage runs of the logical rows: logical cells [i, i + count)
// are storage cells [s, s + count). A logical row is its circular storage row from column sx0 on,
// wrapping once: two runs.
template <typename F>
void DynamicGrid::ForEachStorageRun(F&& f) const {
  const std::int64_t sx0 = Mod(origin_gx_, nx_);
  for (int y = 0; y < ny_; ++y) {
    const std::int64_t row = Mod(origin_gy_ + y, ny_) * nx_;
    const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(nx_);
    f(i, row + sx0, nx_ - sx0);
    f(i + static_cast<std::size_t>(nx_ - sx0), row, sx0);
  }
}

CellState DynamicGrid::Cell(CellIndex c) const {
  if (c.x < 0 || c.y < 0 || c.x >= nx_ || c.y >= ny_) {
    throw std::out_of_range("DynamicGrid::Cell: index (" + std::to_string(c.x) + ", " +
                            std::to_string(c.y) + ") outside " + std::to_string(nx_) + " x " +
                            std::to_string(ny_));
  }
  const std::int64_t s = Storage(origin_gx_ + c.x, origin_gy_ + c.y);
  CellState out;
  out.free = free_[s];
  out.static_occ = static_[s];
  out.dynamic = dynamic_[s];
  out.unknown = std::max(0.0, 1.0 - out.free - out.static_occ - out.dynamic);
  // Velocity statistics on demand from the weighted particles of the last update (sorted_ and
  // its cell ranges stay valid until the next Update): saves five layers of memory traffic.
  const std::int64_t lo = cell_start_[s], hi = cell_start_[s + 1];
  const double wsum = MeanVelocity(sorted_, lo, hi, out.mean_velocity);
  if (wsum > 0.0) {
    Matrix2 cov = Matrix2::Zero();
    for (std::int64_t i = lo; i < hi; ++i) {
      const Vector2 e(sorted_.vx[i] - out.mean_velocity.x(), sorted_.vy[i] - out.mean_velocity.y());
      cov += sorted_.weight[i] * e * e.transpose();
    }
    out.velocity_cov = cov / wsum;
  }
  out.observed = (view_[s] & kObserved) != 0;
  return out;
}

void DynamicGrid::ExportMasses(std::span<float> free, std::span<float> static_occ,
                               std::span<float> dynamic, std::span<std::uint8_t> observed) const {
  const std::size_t n = static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_);
  if (free.size() != n || static_occ.size() != n || dynamic.size() != n || observed.size() != n)
    throw std::invalid_argument(
        "DynamicGrid::ExportMasses: spans of " + std::to_string(free.size()) + "/" +
        std::to_string(static_occ.size()) + "/" + std::to_string(dynamic.size()) + "/" +
        std::to_string(observed.size()) + " entries for " + std::to_string(n) + " cells");
  // Each run a plain loop the compiler vectorises.
  static_assert(kObserved == 1, "observed[] is 0 or 1");
  ForEachStorageRun([&](std::size_t i, std::int64_t s, std::int64_t count) {
    const double* const f = free_.data() + s;
    const double* const st = static_.data() + s;
    const double* const d = dynamic_.data() + s;
    const std::uint8_t* const v = view_.data() + s;
    for (std::int64_t k = 0; k < count; ++k) {
      free[i + k] = static_cast<float>(f[k]);
      static_occ[i + k] = static_cast<float>(st[k]);
      dynamic[i + k] = static_cast<float>(d[k]);
      observed[i + k] = static_cast<std::uint8_t>(v[k] & kObserved);  // 0 or 1
    }
  });
}

void DynamicGrid::ExportMeanVelocities(std::span<float> mean_vx, std::span<float> mean_vy) const {
  const std::size_t n = static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_);
  if (mean_vx.size() != n || mean_vy.size() != n)
    throw std::invalid_argument(
        "DynamicGrid::ExportMeanVelocities: spans of " + std::to_string(mean_vx.size()) + "/" +
        std::to_string(mean_vy.size()) + " entries for " + std::to_string(n) + " cells");
  ForEachStorageRun([&](std::size_t i, std::int64_t s, std::int64_t count) {
    const std::int64_t* const start = cell_start_.data() + s;
    for (std::int64_t k = 0; k < count; ++k) {
      Velocity mean = Velocity::Zero();
      if (start[k] != start[k + 1]) MeanVelocity(sorted_, start[k], start[k + 1], mean);
      mean_vx[i + k] = static_cast<float>(mean.x());
      mean_vy[i + k] = static_cast<float>(mean.y());
    }
  });
}

}  // namespace dualgrid::filter
