#include "dualgrid/outputs/weight_traces.hpp"

#include <algorithm>
#include <cmath>

namespace dualgrid::outputs {

namespace {
constexpr double kBoundsMargin = 1e-6;  // [m]
}  // namespace

void WeightTraces::Add(const cosim::Pipeline& pipeline, std::size_t mode) {
  const sim::Frame& f = pipeline.frame();
  const auto& grid = pipeline.grid(mode);
  const auto& p = grid.particles();
  const GridFrame& g = pipeline.grid_frame();
  std::set<std::string> in_grid;
  for (const auto& v : f.vehicles) {
    const OrientedBox box = g.ToGrid(v.box);  // particles live in the grid frame
    const Velocity velocity = g.VectorToGrid(v.velocity);
    if (!grid.CellOf(box.center)) continue;
    ++frames_in_grid[v.id];
    in_grid.insert(v.id);
    if (dropped.count(v.id)) continue;
    double wp = 0, wv = 0, w = 0, wp_good = 0, wv_good = 0;
    const OrientedBox grown_box{box.center, box.yaw, box.length + 1.0, box.width + 1.0};
    const BoxTest grown(grown_box);
    // The box's axis-aligned bounds with a margin far above Contains' rounding: a cheap first
    // test that passes every particle Contains accepts (so the sums below are unchanged).
    Position lo = grown_box.center, hi = grown_box.center;
    for (const Position& c : grown_box.Corners()) lo = lo.cwiseMin(c), hi = hi.cwiseMax(c);
    lo -= Position::Constant(kBoundsMargin);
    hi += Position::Constant(kBoundsMargin);
    for (std::size_t i = 0; i < p.size(); ++i) {
      const double x = p.x[i], y = p.y[i];
      if (x < lo.x() || x > hi.x() || y < lo.y() || y > hi.y()) continue;
      if (!grown.Contains(Position(x, y))) continue;
      wp += p.w_position[i];
      wv += p.w_velocity[i];
      w += p.weight[i];
      if ((Velocity(p.vx[i], p.vy[i]) - velocity).norm() < WeightTrace::kGoodVelocity) {
        wp_good += p.w_position[i];
        wv_good += p.w_velocity[i];
      }
    }
    int n = 0, tangential = 0;
    const int vehicle_id = pipeline.ids().Find(v.id).value_or(-2);  // scanned: registered
    for (const auto& d : pipeline.detections())
      if (d.source_id == vehicle_id) {
        tangential += std::abs(d.radial_speed_compensated) < 0.5 * v.velocity.norm();
        ++n;
      }
    auto& t = by_vehicle[v.id];
    t.time.push_back(f.time);
    t.w_position.push_back(wp);
    t.w_velocity.push_back(wv);
    t.weight.push_back(w);
    t.position_share.push_back(wp > 0 ? wp_good / wp : std::nan(""));
    t.velocity_share.push_back(wv > 0 ? wv_good / wv : std::nan(""));
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
