// One co-simulation: SUMO steps, the radar model scans the ground truth, and any number of grid
// filters (one per weight mode) consume the same detections. Shared by sim, snapshot and run.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dualgrid/core/grid_frame.hpp"
#include "dualgrid/eval/association.hpp"
#include "dualgrid/filter/dynamic_grid.hpp"
#include "dualgrid/radar_model/radar_model.hpp"
#include "dualgrid/scenario/loader.hpp"
#include "dualgrid/sim/sumo_simulation.hpp"

namespace dualgrid::tools {

/// Stable integer ids for named things (radar source ids, evaluation object ids): static
/// obstacles first, vehicles in order of first appearance (deterministic: frames are sorted).
class IdRegistry {
 public:
  int Id(const std::string& name);
  /// The id of a name already registered.
  std::optional<int> Find(const std::string& name) const;
  const std::string& Name(int id) const;  ///< "clutter" for -1

 private:
  std::map<std::string, int> ids_;
  std::vector<std::string> names_;
};

/// Throws std::invalid_argument, naming the scenario file and its filter keys, when `modes`
/// filters of `config` would need more than 80 % of this machine's physical memory
/// (FilterParams::MemoryBytes); returns `config`. Call before writing anything.
const scenario::ScenarioConfig& CheckFilterMemory(const scenario::ScenarioConfig& config,
                                                  std::size_t modes);

class Pipeline {
 public:
  Pipeline(const scenario::ScenarioConfig& config, const std::filesystem::path& network_dir,
           const std::filesystem::path& work_dir, std::vector<filter::WeightMode> modes);

  /// Advances SUMO one step, scans the due radars and updates every filter. False at the end.
  bool Step();
  /// The first half of Step(): SUMO and the radars, and the filters' inputs. False at the end.
  bool Advance();
  /// The second half for one filter: independent per filter, so callers may run the filters
  /// concurrently (each with a one-thread team inside; docs/performance.md).
  void UpdateFilter(std::size_t i);

  const scenario::ScenarioConfig& config() const { return config_; }
  const sim::Frame& frame() const { return simulation_.frame(); }
  const sim::SumoSimulation& simulation() const { return simulation_; }
  const radar::RadarModel& radar() const { return radar_; }
  /// Detections of the last step (only sensors that were due).
  const std::vector<radar::Detection>& detections() const { return detections_; }
  /// Sensors that scanned in the last step.
  const std::vector<int>& scanned() const { return scanned_; }
  const radar::EgoMotion& ego_motion() const { return ego_; }
  std::size_t num_filters() const { return filters_.size(); }
  filter::WeightMode mode(std::size_t i) const { return modes_[i]; }
  const filter::DynamicGrid& grid(std::size_t i) const { return *filters_[i]; }
  IdRegistry& ids() { return ids_; }
  const IdRegistry& ids() const { return ids_; }

  /// The grid frame (docs/algorithm.md, "Grid frame"): fixed at the first Advance() from the
  /// scenario's `filter.frame` and the ego's heading then; identity before.
  const GridFrame& grid_frame() const { return grid_frame_; }

  /// Ground-truth vehicles (ego excluded) as evaluation objects for a grid, in the grid frame
  /// (boxes and velocities: the clusters' frame): in_grid when the centre lies in the grid,
  /// in_coverage when the centre lies in some radar's field of view.
  std::vector<eval::TruthObject> TruthObjects(const filter::DynamicGrid& grid);

 private:
  radar::Scene BuildScene();

  scenario::ScenarioConfig config_;
  IdRegistry ids_;
  sim::SumoSimulation simulation_;
  radar::RadarModel radar_;
  std::vector<filter::WeightMode> modes_;
  std::vector<std::unique_ptr<filter::DynamicGrid>> filters_;
  radar::Scene static_scene_;
  radar::EgoMotion ego_;
  std::vector<radar::Detection> detections_;
  std::vector<int> scanned_;
  std::vector<filter::Measurement> measurements_;
  std::vector<filter::SensorCoverage> coverage_;
  double last_time_ = 0.0;
  double dt_ = 0.0;  // of the last Advance() [s]
  GridFrame grid_frame_;
  bool frame_fixed_ = false;
  Vector2 centre_offset_ = Vector2::Zero();  // ego -> grid centre, grid frame [m]
};

}  // namespace dualgrid::tools
