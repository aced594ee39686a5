// The multipath pass of one sensor's scan (internal to radar_model/src): ghost scatterers of the
// scene's boxes mirrored in guard rails and in the flat sides of large vehicles
// (docs/radar.md, "Multipath"). They join the direct scatterers before resolution-cell merging, so
// they go through the same detection and noise model.
#pragma once

#include <functional>
#include <vector>

#include "dualgrid/radar_model/multipath.hpp"
#include "dualgrid/radar_model/radar_model.hpp"
#include "scan_geometry.hpp"

namespace dualgrid::radar::detail {

/// One sensor as the scan sees it. `body` is the ego's body (shrunk by its skin), tested only
/// when `has_body`.
struct SensorView {
  const SensorParams* params = nullptr;
  const SensorModel* model = nullptr;
  Position s = Position::Zero();           ///< sensor position, world [m]
  Velocity vs = Velocity::Zero();          ///< sensor velocity over ground [m/s]
  Matrix2 to_local = Matrix2::Identity();  ///< world -> sensor frame rotation
  double cos_half_fov = 0.0;               ///< cos(fov / 2)
  bool occlusion = true;
  bool has_body = false;
  Occluder body;
  Aabb body_box;  ///< the body's bounding box, world
};

/// The scan's own line-of-sight test from the sensor to `q` (true: hidden), ignoring the
/// occluder `owner`; `truth` is q's polar position (q inside the field of view and range).
using DirectHidden = std::function<bool(const Position& q, int owner, const Polar& truth)>;

/// Appends to `out` the ghost scatterers of every box of `scene` in every mirror `mp` enables,
/// for the paths up to mp.max_bounces, that pass the field of view, window, reflector-extent and
/// occlusion tests. `direct_hidden` tests the direct leg of the order-2 paths.
void AddGhostScatterers(const SensorView& view, const MultipathParams& mp, const Scene& scene,
                        const DirectHidden& direct_hidden, std::vector<Scatterer>* out);

}  // namespace dualgrid::radar::detail
