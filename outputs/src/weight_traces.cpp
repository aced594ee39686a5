#include "dualgrid/outputs/weight_traces.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace dualgrid::outputs {

namespace {

constexpr double kBoundsMargin = 1e-6;  // [m]
// Width of the x strips that narrow down which boxes a particle can be in [m]: about a car's
// grown length, so a particle is tested against the one to three vehicles near it.
constexpr double kStripWidth = 4.0;
constexpr std::size_t kMaxStrips = 4096;

// A box to sum over: its containment test, its axis-aligned bounds with a margin far above
// Contains' rounding (a cheap first test that passes every particle Contains accepts), and the
// velocity [m/s] a particle's must be near to count as good.
struct Target {
  BoxTest box;
  Position lo, hi;
  Velocity velocity;
};

Target MakeTarget(const OrientedBox& box, const Velocity& velocity) {
  Position lo = box.center, hi = box.center;
  for (const Position& c : box.Corners()) lo = lo.cwiseMin(c), hi = hi.cwiseMax(c);
  lo -= Position::Constant(kBoundsMargin);
  hi += Position::Constant(kBoundsMargin);
  return {BoxTest(box), lo, hi, velocity};
}

}  // namespace

std::vector<BoxWeights> SumWeightsInBoxes(const filter::ParticleSet& p,
                                          const std::vector<OrientedBox>& boxes,
                                          const std::vector<Velocity>& velocities) {
  assert(boxes.size() == velocities.size());
  std::vector<BoxWeights> sums(boxes.size());
  if (boxes.empty()) return sums;
  std::vector<Target> targets;
  for (std::size_t k = 0; k < boxes.size(); ++k)
    targets.push_back(MakeTarget(boxes[k], velocities[k]));
  // Each particle is tested only against the boxes whose x bounds meet its strip. The strip of x,
  // floor((x - x0) / width), is monotonic in x, so a particle within a box's x bounds lies in one
  // of the strips the box is listed in.
  double x0 = targets[0].lo.x(), x1 = targets[0].hi.x();
  for (const Target& t : targets) x0 = std::min(x0, t.lo.x()), x1 = std::max(x1, t.hi.x());
  const double width = std::max(kStripWidth, (x1 - x0) / static_cast<double>(kMaxStrips - 1));
  const auto strip = [&](double x) { return static_cast<std::size_t>((x - x0) / width); };
  std::vector<std::vector<std::size_t>> listed(strip(x1) + 1);
  for (std::size_t k = 0; k < targets.size(); ++k)
    for (std::size_t s = strip(targets[k].lo.x()); s <= strip(targets[k].hi.x()); ++s)
      listed[s].push_back(k);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double x = p.x[i], y = p.y[i];
    if (!(x >= x0 && x <= x1)) continue;
    for (const std::size_t k : listed[strip(x)]) {
      const Target& t = targets[k];
      if (x < t.lo.x() || x > t.hi.x() || y < t.lo.y() || y > t.hi.y()) continue;
      if (!t.box.Contains(Position(x, y))) continue;
      BoxWeights& b = sums[k];
      b.position += p.w_position[i];
      b.velocity += p.w_velocity[i];
      b.weight += p.weight[i];
      if ((Velocity(p.vx[i], p.vy[i]) - t.velocity).norm() < WeightTrace::kGoodVelocity) {
        b.position_good += p.w_position[i];
        b.velocity_good += p.w_velocity[i];
      }
    }
  }
  return sums;
}

void WeightTraces::Add(const cosim::Pipeline& pipeline, std::size_t mode) {
  const sim::Frame& f = pipeline.frame();
  const auto& grid = pipeline.grid(mode);
  const GridFrame& g = pipeline.grid_frame();
  std::set<std::string> in_grid;
  std::vector<const sim::VehicleState*> traced;
  std::vector<OrientedBox> boxes;  // grown by 1 m: particles spread around a vehicle
  std::vector<Velocity> velocities;
  for (const auto& v : f.vehicles) {
    const OrientedBox box = g.ToGrid(v.box);  // particles live in the grid frame
    if (!grid.CellOf(box.center)) continue;
    ++frames_in_grid[v.id];
    in_grid.insert(v.id);
    if (dropped.count(v.id)) continue;
    traced.push_back(&v);
    boxes.push_back({box.center, box.yaw, box.length + 1.0, box.width + 1.0});
    velocities.push_back(g.VectorToGrid(v.velocity));
  }
  const std::vector<BoxWeights> sums = traced.empty()
                                           ? std::vector<BoxWeights>{}
                                           : SumWeightsInBoxes(grid.particles(), boxes, velocities);
  for (std::size_t k = 0; k < traced.size(); ++k) {
    const sim::VehicleState& v = *traced[k];
    const BoxWeights& b = sums[k];
    int n = 0, tangential = 0;
    const int vehicle_id = pipeline.ids().Find(v.id).value_or(-2);  // scanned: registered
    for (const auto& d : pipeline.detections())
      if (d.source_id == vehicle_id) {
        tangential += std::abs(d.radial_speed_compensated) < 0.5 * v.velocity.norm();
        ++n;
      }
    auto& t = by_vehicle[v.id];
    t.time.push_back(f.time);
    t.w_position.push_back(b.position);
    t.w_velocity.push_back(b.velocity);
    t.weight.push_back(b.weight);
    t.position_share.push_back(b.position > 0 ? b.position_good / b.position : std::nan(""));
    t.velocity_share.push_back(b.velocity > 0 ? b.velocity_good / b.velocity : std::nan(""));
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
