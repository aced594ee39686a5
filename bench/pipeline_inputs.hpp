// What the benchmarks on a co-simulation's own inputs share (bench_floor_e2e,
// bench_measurement_grid): the filters' inputs of its last step, and the process's CPU time.
#pragma once

#include <ctime>
#include <vector>

#include "dualgrid/cosim/pipeline.hpp"
#include "dualgrid/filter/measurement_grid.hpp"

namespace dualgrid::bench {

/// The process's CPU time so far, all threads [s].
inline double ProcessCpu() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

/// The filters' inputs of the last step of `p`: the detections outside the ego's box, the
/// scanned sensors' fields of view and the grid centre, in the grid frame, as
/// Pipeline::FilterInputs makes them for the filters.
inline void PipelineInputs(const cosim::Pipeline& p, std::vector<filter::Measurement>* z,
                           std::vector<filter::SensorCoverage>* coverage, Position* centre) {
  const GridFrame& g = p.grid_frame();
  const BoxTest ego_box(p.frame().ego.box);
  z->clear();
  for (const radar::Detection& d : p.detections()) {
    if (ego_box.Contains(d.position_world)) continue;
    z->push_back({g.ToGrid(d.position_world), g.VectorToGrid(d.radial_velocity_world),
                  g.ToGrid(d.sensor_position_world)});
  }
  coverage->clear();
  const Pose2& ego = p.source().ego().pose;
  for (int s : p.scanned()) {
    const radar::SensorParams& sp = p.radar().sensors()[s];
    const Pose2 pose = p.radar().SensorPose(s, ego);
    coverage->push_back(
        {g.ToGrid(pose.position), g.YawToGrid(pose.yaw), 0.5 * sp.fov, sp.min_range, sp.max_range});
  }
  *centre = g.ToGrid(p.GridFootprint().center);
}

}  // namespace dualgrid::bench
