#include "dualgrid/outputs/weight_traces.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string_view>

namespace dualgrid::outputs {

namespace {
constexpr double kBoundsMargin = 1e-6;  // [m]

// `a` if `keep`, else +0.0, without a branch (which particles move with the box is unpredictable).
// Adding +0.0 leaves a sum's bits alone unless the sum is -0.0, and the sums below start at +0.0,
// so never are: they equal the sums of the kept values alone.
inline double KeepIf(double a, bool keep) {
  return std::bit_cast<double>(std::bit_cast<std::uint64_t>(a) & -static_cast<std::uint64_t>(keep));
}
}  // namespace

ParticleRuns::ParticleRuns(const filter::ParticleSet& particles) : p_(particles) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const std::size_t n = p_.size();
  bounds_.resize(4 * ((n + kRun - 1) / kRun));
  for (std::size_t first = 0, r = 0; first < n; first += kRun, r += 4) {
    double x_lo = kInf, x_hi = -kInf, y_lo = kInf, y_hi = -kInf;
    for (std::size_t i = first, end = std::min(n, first + kRun); i < end; ++i) {
      const double x = p_.x[i], y = p_.y[i];
      // A NaN coordinate fails every comparison and is left out: BoxTest rejects it anyway.
      x_lo = x < x_lo ? x : x_lo;
      x_hi = x > x_hi ? x : x_hi;
      y_lo = y < y_lo ? y : y_lo;
      y_hi = y > y_hi ? y : y_hi;
    }
    bounds_[r] = x_lo, bounds_[r + 1] = x_hi, bounds_[r + 2] = y_lo, bounds_[r + 3] = y_hi;
  }
}

BoxWeights ParticleRuns::Sum(const OrientedBox& box, const Velocity& velocity) const {
  const BoxTest inside(box);
  // The box's axis-aligned bounds with a margin far above Contains' rounding: a cheap first
  // test that passes every particle Contains accepts. A run is skipped only when all its
  // particles fail this same test, so the particles summed and their order are those of a scan
  // of every particle.
  Position lo = box.center, hi = box.center;
  for (const Position& c : box.Corners()) lo = lo.cwiseMin(c), hi = hi.cwiseMax(c);
  lo -= Position::Constant(kBoundsMargin);
  hi += Position::Constant(kBoundsMargin);
  // Local accumulators and a copy of `velocity`: kept in registers (a reference or the returned
  // struct might alias the particle arrays as far as the compiler knows).
  const Velocity v = velocity;
  double wp = 0.0, wv = 0.0, w = 0.0, wp_good = 0.0, wv_good = 0.0;
  const std::size_t n = p_.size();
  for (std::size_t first = 0, r = 0; first < n; first += kRun, r += 4) {
    if (bounds_[r + 1] < lo.x() || bounds_[r] > hi.x() || bounds_[r + 3] < lo.y() ||
        bounds_[r + 2] > hi.y())
      continue;
    for (std::size_t i = first, end = std::min(n, first + kRun); i < end; ++i) {
      const double x = p_.x[i], y = p_.y[i];
      if (x < lo.x() || x > hi.x() || y < lo.y() || y > hi.y()) continue;
      if (!inside.Contains(Position(x, y))) continue;
      const bool good = (Velocity(p_.vx[i], p_.vy[i]) - v).norm() < WeightTrace::kGoodVelocity;
      const double pw = p_.w_position[i], vw = p_.w_velocity[i];
      wp += pw;
      wv += vw;
      w += p_.weight[i];
      wp_good += KeepIf(pw, good);
      wv_good += KeepIf(vw, good);
    }
  }
  return {wp, wv, w, wp_good, wv_good};
}

void WeightTraces::Add(const cosim::Pipeline& pipeline, std::size_t mode) {
  const sim::Frame& f = pipeline.frame();
  const auto& grid = pipeline.grid(mode);
  const GridFrame& g = pipeline.grid_frame();
  std::optional<ParticleRuns> runs;  // built at the first vehicle that needs sums
  std::vector<std::string_view> in_grid;
  for (const auto& v : f.vehicles) {
    const OrientedBox box = g.ToGrid(v.box);  // particles live in the grid frame
    if (!grid.CellOf(box.center)) continue;
    ++frames_in_grid[v.id];
    in_grid.push_back(v.id);
    if (dropped.count(v.id)) continue;
    if (!runs) runs.emplace(grid.particles());
    const OrientedBox grown{box.center, box.yaw, box.length + 1.0, box.width + 1.0};
    const BoxWeights w = runs->Sum(grown, g.VectorToGrid(v.velocity));
    int n = 0, tangential = 0;
    const int vehicle_id = pipeline.ids().Find(v.id).value_or(-2);  // scanned: registered
    for (const auto& d : pipeline.detections())
      if (d.source_id == vehicle_id) {
        tangential += std::abs(d.radial_speed_compensated) < 0.5 * v.velocity.norm();
        ++n;
      }
    auto& t = by_vehicle[v.id];
    t.time.push_back(f.time);
    t.w_position.push_back(w.w_position);
    t.w_velocity.push_back(w.w_velocity);
    t.weight.push_back(w.weight);
    t.position_share.push_back(w.w_position > 0 ? w.w_position_good / w.w_position : std::nan(""));
    t.velocity_share.push_back(w.w_velocity > 0 ? w.w_velocity_good / w.w_velocity : std::nan(""));
    t.tangential_share.push_back(n > 0 ? static_cast<double>(tangential) / n : std::nan(""));
  }
  std::sort(in_grid.begin(), in_grid.end());
  const std::string leader = Focus();
  for (auto it = by_vehicle.begin(); it != by_vehicle.end();) {
    if (it->first != requested && it->first != leader &&
        !std::binary_search(in_grid.begin(), in_grid.end(), std::string_view(it->first))) {
      dropped.insert(it->first);
      it = by_vehicle.erase(it);
    } else {
      ++it;
    }
  }
}

std::string WeightTraces::Focus() const {
  if (by_vehicle.count(requested)) return requested;
  std::string focus;
  int best = -1;
  for (const auto& [id, n] : frames_in_grid)
    if (n > best && by_vehicle.count(id)) best = n, focus = id;
  return focus;
}

}  // namespace dualgrid::outputs
