// The co-simulation's detection source: SUMO steps, the radar model scans the ground truth.
#include <stdexcept>

#include "dualgrid/cosim/detection_source.hpp"
#include "dualgrid/cosim/pipeline.hpp"

namespace dualgrid::cosim {

SumoSource::SumoSource(const scenario::ScenarioConfig& config, IdRegistry& ids) : config_(config) {
  for (const auto& g : config_.sim.guard_rails)
    static_scene_.polylines.push_back({ids.Id(g.id), g.points, g.rcs_dbsm_per_metre});
  for (const auto& p : config_.sim.parked)
    static_scene_.targets.push_back({ids.Id(p.id), p.box, Velocity::Zero(), 0.0, p.rcs_dbsm});
}

void SumoSource::Start(const SourceFolders& folders) {
  simulation_ = std::make_unique<sim::SumoSimulation>(
      config_.sim, sim::ResolveNetwork(config_.sim.network, folders.network_dir), folders.work_dir);
}

void SumoSource::Finish() {
  if (simulation_) simulation_->Close();
}

bool SumoSource::Advance(IdRegistry&) {
  if (!simulation_->Step()) return false;
  const sim::Frame& f = frame();
  ego_ = {f.EgoPose(), f.ego.velocity, f.ego.yaw_rate, f.ego.box.length, f.ego.box.width};
  if (!radar_) {
    // The default radars sit on the ego's box as SUMO simulates it: an ego of the user's route
    // files may not have the scenario type's box (a 5 m SUMO car put the front radar inside it).
    scenario::RadarConfig rig = config_.radar;
    scenario::PlaceRigOn(&rig, f.ego.box.length, f.ego.box.width);
    radar_.emplace(rig.sensors, rig.options, config_.sim.seed);
  }
  return true;
}

void SumoSource::Scan(IdRegistry& ids, std::vector<radar::Detection>* detections,
                      std::vector<int>* scanned) {
  const sim::Frame& f = frame();
  radar::Scene scene = static_scene_;
  for (const sim::VehicleState& v : f.vehicles)
    scene.targets.push_back({ids.Id(v.id), v.box, v.velocity, v.yaw_rate, v.rcs_dbsm});
  *detections = radar_->Scan(ego_, scene, static_cast<std::uint64_t>(f.step), f.time,
                             config_.sim.step_length);
  *scanned = radar_->SensorsDue(f.time, config_.sim.step_length);
}

}  // namespace dualgrid::cosim
