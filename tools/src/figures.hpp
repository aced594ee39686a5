// Pictures of a run, drawn with the viz library (cairo).
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "dualgrid/eval/metrics.hpp"
#include "pipeline.hpp"
#include "scoring.hpp"

namespace dualgrid::tools {

/// Bird's-eye picture of the current step: lanes, guard rails, parked boxes, vehicles, radar
/// fields of view and the step's detections with their radial-velocity arrows. The view spans
/// [ego.x - behind, ego.x + ahead] x [ego.y - half_width, ego.y + half_width].
void RenderScene(const Pipeline& pipeline, const std::filesystem::path& path, double behind,
                 double ahead, double half_width);

/// The paper's Fig. 7: one grid panel per mode at one time, ground-truth boxes outlined.
void RenderGridFigure(const std::vector<std::string>& modes,
                      const std::vector<GridSnapshot>& snapshots, const sim::Frame& frame,
                      double time, const std::filesystem::path& path);

/// The paper's Fig. 6: tracked share D per object and mode.
void RenderTrackedShares(const std::vector<std::string>& modes,
                         const std::vector<eval::ScenarioMetrics>& metrics, const IdRegistry& ids,
                         const std::string& title, const std::filesystem::path& path);

/// Particle weight masses on one object over time (paper Fig. 4).
struct WeightTrace {
  std::vector<double> time, w_position, w_velocity, weight;
  std::vector<double> radial_speed_ratio;  ///< |compensated Doppler| / |velocity| of the object
};
void RenderWeightTrace(const WeightTrace& trace, const std::string& object, const std::string& mode,
                       const std::filesystem::path& path);

}  // namespace dualgrid::tools
