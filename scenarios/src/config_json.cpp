#include "fields.hpp"
#include "sections.hpp"

namespace dualgrid::scenario {
namespace {

using namespace detail;

void WriteSensorProfile(const radar::SensorParams& s, nlohmann::json* j) {
  std::vector<double> deg;
  for (double a : s.off_boresight) deg.push_back(RadToDeg(a));
  (*j)["off_boresight_deg"] = deg;
  (*j)["off_boresight_resolution"] = s.off_boresight_resolution;
  (*j)["off_boresight_accuracy"] = s.off_boresight_accuracy;
}

}  // namespace

nlohmann::json ConfigToJson(const ScenarioConfig& c) {
  nlohmann::json j;
  j["scenario_file"] = c.file.string();
  j["scenario"] = c.sim.name;
  j["overrides"] = c.overrides;
  j["seed"] = c.sim.seed;
  j["begin_s"] = c.sim.begin;  // SUMO time; duration_s counts from it
  j["begin_source"] = c.sim.begin_source;
  j["duration_s"] = c.sim.duration;
  j["step_length_s"] = c.sim.step_length;
  j["sensors"]["accuracy"] = c.radar.accuracy;
  j["sensors"]["noise"] = c.radar.options.noise;
  j["sensors"]["false_alarms"] = c.radar.options.false_alarms;
  j["sensors"]["occlusion"] = c.radar.options.occlusion;
  // Only when on: a run with multipath off writes the same config.json as before it existed.
  if (const radar::MultipathParams& mp = c.radar.options.multipath; mp.enabled)
    j["sensors"]["multipath"] = {{"enabled", mp.enabled},
                                 {"rails", mp.rails},
                                 {"vehicles", mp.vehicles},
                                 {"rail_loss_db", mp.rail_loss_db},
                                 {"vehicle_loss_db", mp.vehicle_loss_db},
                                 {"vehicle_min_length", mp.vehicle_min_length},
                                 {"max_bounces", mp.max_bounces},
                                 {"min_pd", mp.min_pd}};
  for (const auto& s : c.radar.sensors) {
    nlohmann::json sj = {{"name", s.name},
                         {"mount",
                          {{"x", s.mount.position.x()},
                           {"y", s.mount.position.y()},
                           {"yaw_deg", RadToDeg(s.mount.yaw)}}}};
    WriteFields(kSensorDoubles, s, &sj);
    WriteSensorProfile(s, &sj);
    j["sensors"]["rig"].push_back(sj);
  }
  WriteFields(kFilterDoubles, c.filter, &j["filter"]);
  WriteFields(kFilterInts, c.filter, &j["filter"]);
  j["filter"]["mode"] = filter::ToString(c.filter.mode);
  j["filter"]["preset"] = c.filter_preset.empty() ? "default" : c.filter_preset;
  j["filter"]["zero_likelihood"] = filter::ToString(c.filter.zero_likelihood);
  j["filter"]["velocity_likelihood"] = filter::ToString(c.filter.velocity_likelihood);
  j["filter"]["normalisation"] = filter::ToString(c.filter.normalisation);
  j["filter"]["frame"] = ToString(c.grid.frame);
  if (c.grid.frame == GridPlacement::Frame::kFollow)
    j["filter"]["realign_deg"] = c.grid.realign_deg;
  const Vector2 off = c.grid.CentreOffset(c.filter.length_x, c.filter.width_y);
  j["filter"]["ahead"] = 0.5 * c.filter.length_x + off.x();
  j["filter"]["left"] = 0.5 * c.filter.width_y + off.y();
  // Per mode always (the resolved value each filter runs with), so runs compare key by key.
  for (filter::WeightMode m :
       {filter::WeightMode::kPosition, filter::WeightMode::kVelocity, filter::WeightMode::kDual})
    j["filter"]["birth_velocity"][std::string(filter::ToString(m))] =
        filter::ToString(c.FilterFor(m).birth_velocity);
  auto& e = j["evaluation"];
  e["dynamic_threshold"] = c.evaluation.dynamic_threshold;
  e["min_cluster_mass"] = c.evaluation.min_cluster_mass;
  e["dbscan"] = c.evaluation.dbscan;
  e["tracking"] = c.evaluation.tracking;
  e["focus_object"] = c.evaluation.focus_object;
  e["snapshot_times"] = c.evaluation.snapshot_times;
  return j;
}
}  // namespace dualgrid::scenario
