// Step 1 of the cycle (docs/algorithm.md; the paper assumes an ego-motion-compensated grid, Sec.
// III): the grid is centred on the ego by whole-cell shifts of its origin over circular storage, so
// no data moves and no rotation smearing accrues; cells that enter are cleared to unknown.
#include "dualgrid/filter/dynamic_grid.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "dualgrid/core/random.hpp"
#include "grid_internal.hpp"
#include "team.hpp"

namespace dualgrid::filter {

using namespace detail;

void DynamicGrid::InitializeOrigin(const EgoInput& ego) {
  const auto origin = OriginFor(ego.pose.position);
  origin_gx_ = origin[0];
  origin_gy_ = origin[1];
  shift_gx_ = shift_gy_ = 0;
  initialized_ = true;
}

// Particles start spread over the grid with zero weight: the first births replace them.
void DynamicGrid::SpreadParticles(const Team& t) {
  const std::int64_t n = static_cast<std::int64_t>(particles_.size());
  ForStatic(t, n, [&](std::int64_t i) {
    CounterRng rng(seed_, RngPurpose::kFilterInit, 0, static_cast<std::uint32_t>(i));
    particles_.x[i] = static_cast<float>(rng.Uniform() * nx_ * params_.resolution);  // local [m]
    particles_.y[i] = static_cast<float>(rng.Uniform() * ny_ * params_.resolution);
    particles_.vx[i] = particles_.vy[i] = 0.0f;
    particles_.w_position[i] = particles_.w_velocity[i] = particles_.weight[i] = 0.0f;
  });
}

void DynamicGrid::ResetColumn(std::int64_t gx) {
  const std::int64_t sx = Mod(gx, nx_);
  for (std::int64_t sy = 0; sy < ny_; ++sy) {
    const std::int64_t s = sy * nx_ + sx;
    free_[s] = static_[s] = dynamic_[s] = born_[s] = 0.0;
  }
}

void DynamicGrid::ResetRow(std::int64_t gy) {
  const std::int64_t sy = Mod(gy, ny_);
  std::fill_n(free_.begin() + sy * nx_, nx_, 0.0);
  std::fill_n(static_.begin() + sy * nx_, nx_, 0.0);
  std::fill_n(dynamic_.begin() + sy * nx_, nx_, 0.0);
  std::fill_n(born_.begin() + sy * nx_, nx_, 0.0);
}

std::array<std::int64_t, 2> DynamicGrid::OriginFor(const Position& ego) const {
  return detail::OriginFor(ego, params_.resolution, nx_, ny_);
}

void DynamicGrid::ShiftTo(const Position& ego) {
  const auto [gx, gy] = OriginFor(ego);
  const std::int64_t dx = gx - origin_gx_, dy = gy - origin_gy_;
  // Only the storage columns/rows that now represent new world cells are cleared (grid_map
  // style); everything else stays in place and is re-addressed through the new origin.
  if (std::abs(dx) >= nx_ || std::abs(dy) >= ny_) {
    std::fill(free_.begin(), free_.end(), 0.0);
    std::fill(static_.begin(), static_.end(), 0.0);
    std::fill(dynamic_.begin(), dynamic_.end(), 0.0);
    std::fill(born_.begin(), born_.end(), 0.0);
  } else {
    for (std::int64_t c = 0; c < std::abs(dx); ++c)
      ResetColumn(dx > 0 ? origin_gx_ + nx_ + c : gx + c);
    for (std::int64_t c = 0; c < std::abs(dy); ++c)
      ResetRow(dy > 0 ? origin_gy_ + ny_ + c : gy + c);
  }
  // The particles' grid-local coordinates move by the same whole cells (dx r metres), in the
  // prediction's pass (PredictAndSort), which reads every particle anyway.
  shift_gx_ = dx;
  shift_gy_ = dy;
  origin_gx_ = gx;
  origin_gy_ = gy;
}

}  // namespace dualgrid::filter
