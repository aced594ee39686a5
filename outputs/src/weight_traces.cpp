#include "dualgrid/outputs/weight_traces.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace dualgrid::outputs {

namespace {

constexpr double kBoundsMargin = 1e-6;  // [m]
constexpr double kBucket = 4.0;         // [m] of x per bucket of boxes

// A box's axis-aligned bounds with a margin far above Contains' rounding: a cheap first test
// that passes every particle Contains accepts (so the sums are unchanged).
struct Bounds {
  BoxTest test;
  Position lo, hi;
  explicit Bounds(const OrientedBox& box) : test(box), lo(box.center), hi(box.center) {
    for (const Position& c : box.Corners()) lo = lo.cwiseMin(c), hi = hi.cwiseMax(c);
    lo -= Position::Constant(kBoundsMargin);
    hi += Position::Constant(kBoundsMargin);
  }
};

}  // namespace

void SumBoxWeights(const filter::ParticleSet& p, std::vector<BoxWeights>& boxes) {
  if (boxes.empty()) return;
  std::vector<Bounds> bounds;
  bounds.reserve(boxes.size());
  for (const BoxWeights& b : boxes) bounds.emplace_back(b.box);
  double x0 = bounds.front().lo.x(), x1 = bounds.front().hi.x();
  for (const Bounds& b : bounds) x0 = std::min(x0, b.lo.x()), x1 = std::max(x1, b.hi.x());
  // Each particle is tested only against the boxes whose bounds overlap its x bucket; each box
  // adds its particles in index order, as a pass per box does.
  const auto bucket = [&](double x) { return static_cast<long>(std::floor((x - x0) / kBucket)); };
  std::vector<std::vector<std::size_t>> in_bucket(static_cast<std::size_t>(bucket(x1) + 1));
  for (std::size_t k = 0; k < bounds.size(); ++k)
    for (long b = bucket(bounds[k].lo.x()); b <= bucket(bounds[k].hi.x()); ++b)
      in_bucket[static_cast<std::size_t>(b)].push_back(k);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double x = p.x[i], y = p.y[i];
    if (!(x >= x0 && x <= x1)) continue;
    for (const std::size_t k : in_bucket[static_cast<std::size_t>(bucket(x))]) {
      const Bounds& b = bounds[k];
      if (x < b.lo.x() || x > b.hi.x() || y < b.lo.y() || y > b.hi.y()) continue;
      if (!b.test.Contains(Position(x, y))) continue;
      BoxWeights& c = boxes[k];
      c.wp += p.w_position[i];
      c.wv += p.w_velocity[i];
      c.w += p.weight[i];
      if ((Velocity(p.vx[i], p.vy[i]) - c.velocity).norm() < WeightTrace::kGoodVelocity) {
        c.wp_good += p.w_position[i];
        c.wv_good += p.w_velocity[i];
      }
    }
  }
}

void WeightTraces::Add(const cosim::Pipeline& pipeline, std::size_t mode) {
  const sim::Frame& f = pipeline.frame();
  const auto& grid = pipeline.grid(mode);
  const GridFrame& g = pipeline.grid_frame();
  std::set<std::string> in_grid;
  std::vector<const sim::VehicleState*> summed;
  std::vector<BoxWeights> boxes;
  for (const auto& v : f.vehicles) {
    const OrientedBox box = g.ToGrid(v.box);  // particles live in the grid frame
    if (!grid.CellOf(box.center)) continue;
    ++frames_in_grid[v.id];
    in_grid.insert(v.id);
    if (dropped.count(v.id)) continue;
    summed.push_back(&v);
    boxes.push_back(
        {{box.center, box.yaw, box.length + 1.0, box.width + 1.0}, g.VectorToGrid(v.velocity)});
  }
  SumBoxWeights(grid.particles(), boxes);
  for (std::size_t k = 0; k < boxes.size(); ++k) {
    const sim::VehicleState& v = *summed[k];
    const BoxWeights& c = boxes[k];
    int n = 0, tangential = 0;
    const int vehicle_id = pipeline.ids().Find(v.id).value_or(-2);  // scanned: registered
    for (const auto& d : pipeline.detections())
      if (d.source_id == vehicle_id) {
        tangential += std::abs(d.radial_speed_compensated) < 0.5 * v.velocity.norm();
        ++n;
      }
    auto& t = by_vehicle[v.id];
    t.time.push_back(f.time);
    t.w_position.push_back(c.wp);
    t.w_velocity.push_back(c.wv);
    t.weight.push_back(c.w);
    t.position_share.push_back(c.wp > 0 ? c.wp_good / c.wp : std::nan(""));
    t.velocity_share.push_back(c.wv > 0 ? c.wv_good / c.wv : std::nan(""));
    t.tangential_share.push_back(n > 0 ? static_cast<double>(tangential) / n : std::nan(""));
  }
  const std::string leader = Focus();
  for (auto it = by_vehicle.begin(); it != by_vehicle.end();) {
    if (it->first != requested && it->first != leader && !in_grid.count(it->first)) {
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
