// Synthetic single-target scenarios with exact radar detections (no SUMO) for the filter tests.
#pragma once

#include <algorithm>
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "dualgrid/core/types.hpp"
#include "dualgrid/filter/dynamic_grid.hpp"

namespace dualgrid::filter::testing {

/// Exact detection of world point `p` on a body moving with `v`, seen from `sensor`: the
/// compensated radial velocity is the projection of v on the line of sight (eq. 1).
inline Measurement Detect(const Position& p, const Velocity& v, const Position& sensor) {
  const Vector2 los = (p - sensor).normalized();
  return {p, v.dot(los) * los, sensor};
}

/// Points spaced `spacing` apart on the face of `box` nearest to `sensor`, restricted to within
/// `half_span` of the foot of the perpendicular from the sensor (where a flat face reflects).
inline std::vector<Position> NearFacePoints(const OrientedBox& box, const Position& sensor,
                                            double half_span, double spacing) {
  const auto c = box.Corners();  // FL, RL, RR, FR
  // Pick the edge whose outward normal faces the sensor most.
  int best = 0;
  double best_dot = -1e300;
  for (int e = 0; e < 4; ++e) {
    const Position a = c[e], b = c[(e + 1) % 4];
    const Vector2 mid = 0.5 * (a + b);
    const Vector2 out = (mid - box.center).normalized();
    const double d = out.dot((sensor - mid).normalized());
    if (d > best_dot) {
      best_dot = d;
      best = e;
    }
  }
  const Position a = c[best], b = c[(best + 1) % 4];
  const Vector2 u = (b - a).normalized();
  const double len = (b - a).norm();
  const double foot = std::clamp((sensor - a).dot(u), 0.0, len);
  std::vector<Position> out;
  for (double t = -half_span; t <= half_span + 1e-9; t += spacing) {
    const double s = foot + t;
    if (s >= 0.0 && s <= len) out.push_back(a + s * u);
  }
  return out;
}

/// Long-range radar at the front of the ego, looking along its heading.
inline SensorCoverage ForwardRadar(const Pose2& ego) {
  return {ego.ToParent({2.0, 0.0}), ego.yaw, DegToRad(10.0), 0.5, 200.0};
}
/// Side radar on the left of the ego, looking left.
inline SensorCoverage LeftRadar(const Pose2& ego) {
  return {ego.ToParent({0.0, 0.9}), WrapAngle(ego.yaw + 0.5 * kPi), DegToRad(60.0), 0.3, 80.0};
}

/// Result of looking at the grid around a known target.
struct TargetView {
  double max_dynamic = 0.0;                   ///< Max P(dynamic) of cells inside the (dilated) box.
  double max_static = 0.0;                    ///< Max P(static) of cells inside the (dilated) box.
  Velocity mean_velocity = Velocity::Zero();  ///< Weighted mean of particles in the box.
  double particle_mass = 0.0;                 ///< Sum of particle weights in the box.
  bool has_particles = false;
};

/// Grid: DynamicGrid, or the double reference filter_ref::DynamicGrid (test_float_bound.cpp).
template <typename Grid>
TargetView LookAt(const Grid& grid, OrientedBox box, double margin) {
  box.length += 2.0 * margin;
  box.width += 2.0 * margin;
  TargetView v;
  const double r = grid.resolution();
  const double reach = 0.5 * std::hypot(box.length, box.width) + r;
  for (double y = box.center.y() - reach; y <= box.center.y() + reach; y += r) {
    for (double x = box.center.x() - reach; x <= box.center.x() + reach; x += r) {
      const auto c = grid.CellOf({x, y});
      if (!c || !box.Contains(grid.CellCenter(*c))) continue;
      const auto s = grid.Cell(*c);
      v.max_dynamic = std::max(v.max_dynamic, s.dynamic);
      v.max_static = std::max(v.max_static, s.static_occ);
    }
  }
  const auto& p = grid.particles();
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!box.Contains({p.x[i], p.y[i]})) continue;
    v.mean_velocity += p.weight[i] * Velocity(p.vx[i], p.vy[i]);
    v.particle_mass += p.weight[i];
  }
  if (v.particle_mass > 0.0) {
    v.mean_velocity /= v.particle_mass;
    v.has_particles = true;
  }
  return v;
}

enum class Case { kRadial, kTangential, kStatic };

struct Trace {
  std::vector<TargetView> views;    // one per cycle
  std::vector<std::string> broken;  // invariant violations, "cycle k: ..."
};

// dt = 0.05 s (the radar cycle of the project), 3 s. Car 4.5 m x 1.8 m at 25 m/s (90 km/h).
//  kRadial: ego at rest, target ahead driving away along the long-range radar's line of sight
//           (compensated radial speed = 25 m/s), detections on its rear face.
//  kTangential: ego and target both at 25 m/s along x, target 9 m to the left, seen by the left
//           radar abeam: the line of sight is perpendicular to the motion, detections near the
//           foot point of the side face (+-0.6 m, so |v_r| <= 25 * 0.6 / 8 = 1.9 m/s).
//  kStatic: parked box 30 m ahead of the resting ego, zero Doppler.
// From cycle `silent_from` on the sensor still observes but reports no detection (a missed target).
template <typename Grid = DynamicGrid>
Trace Run(Case c, FilterParams fp, std::uint64_t seed, int cycles = 60, int silent_from = 1 << 30) {
  Grid g(fp, seed);
  const double dt = 0.05;
  Trace tr;
  for (int k = 0; k < cycles; ++k) {
    const double t = k * dt;
    Pose2 ego;
    Velocity ego_v = Velocity::Zero();
    OrientedBox box{{0, 0}, 0.0, 4.5, 1.8};
    Velocity v = Velocity::Zero();
    SensorCoverage cov;
    double half_span = 1.0;
    switch (c) {
      case Case::kRadial:
        box.center = {20.0 + 25.0 * t, 0.3};
        v = {25.0, 0.0};
        cov = ForwardRadar(ego);
        break;
      case Case::kTangential:
        ego.position = {25.0 * t, 0.0};
        ego_v = {25.0, 0.0};
        box.center = {25.0 * t, 9.0};
        v = {25.0, 0.0};
        cov = LeftRadar(ego);
        half_span = 0.6;
        break;
      case Case::kStatic:
        box.center = {30.0, 1.0};
        cov = ForwardRadar(ego);
        break;
    }
    std::vector<Measurement> z;
    if (k < silent_from) {
      for (const Position& p : NearFacePoints(box, cov.origin, half_span, 0.5)) {
        z.push_back(Detect(p, v, cov.origin));
      }
    }
    g.Update({ego, ego_v}, z, std::span<const SensorCoverage>(&cov, 1), dt);
    if (const auto b = g.CheckInvariants())
      tr.broken.push_back("cycle " + std::to_string(k) + ": " + *b);
    TargetView view = LookAt(g, box, 0.5);
    view.mean_velocity -= v;  // store the error vector
    tr.views.push_back(view);
  }
  return tr;
}

// Mean velocity error norm over cycles [from, to).
inline double MeanVelocityError(const Trace& t, int from, int to) {
  double s = 0.0;
  for (int k = from; k < to; ++k) s += t.views[k].mean_velocity.norm();
  return s / (to - from);
}

inline Trace Run(Case c, WeightMode mode, std::uint64_t seed, int cycles = 60) {
  FilterParams fp;
  fp.mode = mode;
  return Run(c, fp, seed, cycles);
}

}  // namespace dualgrid::filter::testing
