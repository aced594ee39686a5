#include "step_data.hpp"

#include "dualgrid/eval/cell_metrics.hpp"

namespace dualgrid::python {
namespace {

void CopyDetections(const cosim::StepView& v, StepData* d) {
  const auto& labels = v.pipeline.labels();
  const auto& dets = v.pipeline.detections();
  d->detections.reserve(dets.size());
  for (std::size_t i = 0; i < dets.size(); ++i) {
    const radar::Detection& x = dets[i];
    d->detections.push_back({x.sensor, x.range, x.azimuth, x.range_rate, x.snr_db,
                             x.position_world.x(), x.position_world.y(), x.position_ego.x(),
                             x.position_ego.y(), x.radial_speed_compensated,
                             x.radial_velocity_world.x(), x.radial_velocity_world.y(),
                             x.sensor_position_world.x(), x.sensor_position_world.y(), x.source_id,
                             x.is_clutter, i < labels.size() ? labels[i] : -1});
  }
}

void CopyTruth(const cosim::StepView& v, StepData* d) {
  const GridFrame& g = v.pipeline.grid_frame();
  for (const eval::TruthObject& o : v.objects) {
    const Position p = g.ToWorld(o.box.center);
    const Velocity u = g.VectorToWorld(o.velocity);
    d->truth.push_back({o.id, p.x(), p.y(), g.YawToWorld(o.box.yaw), o.box.length, o.box.width,
                        u.x(), u.y(), o.in_grid, o.in_coverage, o.detected_in_grid});
    d->names.emplace_back(o.id, v.pipeline.ids().Name(o.id));
  }
}

GridData CopyGrid(const cosim::StepView& v, std::size_t m) {
  const cosim::GridSnapshot& s = v.snapshots[m];
  GridData g;
  g.cells_x = s.cells_x;
  g.cells_y = s.cells_y;
  g.resolution = s.resolution;
  g.origin_ix = s.origin_ix;
  g.origin_iy = s.origin_iy;
  const std::size_t n = s.dynamic.size();
  g.masses.resize(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    g.masses[3 * i] = s.free[i];
    g.masses[3 * i + 1] = s.static_occ[i];
    g.masses[3 * i + 2] = s.dynamic[i];
  }
  if (s.mean_vx.size() == n) {
    g.velocity.resize(2 * n);
    for (std::size_t i = 0; i < n; ++i) {
      g.velocity[2 * i] = s.mean_vx[i];
      g.velocity[2 * i + 1] = s.mean_vy[i];
    }
  }
  g.observed = s.observed;
  g.classes = s.classes;
  if (g.classes.size() != n) {  // the scorer's classes (ClassifySnapshot) unless a step failed
    g.classes.resize(n);
    eval::ClassifyCells(s.free, s.static_occ, s.dynamic,
                        v.pipeline.config().evaluation.dynamic_threshold, g.classes);
  }
  // DynamicGrid::CellCenter's arithmetic.
  for (int i = 0; i < s.cells_x; ++i)
    g.x.push_back((static_cast<double>(s.origin_ix + i) + 0.5) * s.resolution);
  for (int i = 0; i < s.cells_y; ++i)
    g.y.push_back((static_cast<double>(s.origin_iy + i) + 0.5) * s.resolution);
  if (v.truth_classes.size() == n)
    for (std::size_t i = 0; i < n; ++i)
      if (s.observed[i]) ++g.confusion[v.truth_classes[i]][g.classes[i]];

  const GridFrame& frame = v.pipeline.grid_frame();
  const auto& a = v.scorers[m].association();
  const auto& clusters = v.scorers[m].clusters();
  for (std::size_t c = 0; c < clusters.size(); ++c) {
    const Position p = frame.ToWorld(clusters[c].position);
    const Velocity u = frame.VectorToWorld(clusters[c].velocity);
    const int o = a.object_of_cluster[c];
    g.clusters.push_back({p.x(), p.y(), u.x(), u.y(), clusters[c].weight, clusters[c].size,
                          static_cast<std::int8_t>(a.role[c]), o >= 0 ? v.objects[o].id : -1});
  }
  g.matched = a.num_matched;
  g.duplicate = a.num_duplicate;
  g.false_clusters = a.num_false;
  for (int c : a.cluster_of_object) g.objects_matched += c >= 0;
  return g;
}

}  // namespace

std::shared_ptr<const StepData> CopyStep(const cosim::StepView& v) {
  auto d = std::make_shared<StepData>();
  d->step = v.frame.step;
  d->time = v.frame.time;
  const sim::VehicleState& ego = v.frame.ego;
  d->ego_x = ego.box.center.x();
  d->ego_y = ego.box.center.y();
  d->ego_yaw = ego.box.yaw;
  d->ego_vx = ego.velocity.x();
  d->ego_vy = ego.velocity.y();
  d->grid_yaw = v.pipeline.grid_frame().yaw();
  CopyDetections(v, d.get());
  CopyTruth(v, d.get());
  d->truth_classes = v.truth_classes;
  d->modes = v.mode_names;
  for (std::size_t m = 0; m < v.snapshots.size(); ++m) d->grids.push_back(CopyGrid(v, m));
  return d;
}

}  // namespace dualgrid::python
