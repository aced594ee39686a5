#include "output.hpp"

#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace dualgrid::tools {

std::string Fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

scenario::ScenarioConfig LoadConfig(const RunOptions& options) {
  scenario::ScenarioConfig config = scenario::LoadScenario(options.scenario);
  if (options.seed) config.sim.seed = *options.seed;
  if (options.duration) config.sim.duration = *options.duration;
  // The overrides go through the same validation as the file.
  std::string error;
  if (!config.sim.IsValid(&error))
    throw std::invalid_argument(config.file.string() +
                                " with the command-line overrides: " + error);
  return config;
}

void CopyScenario(const scenario::ScenarioConfig& config, const std::filesystem::path& out) {
  std::ifstream in(config.file);
  std::ofstream copy = OpenOutput(out / "scenario.yaml");
  copy << "# Copy of " << config.file.string() << " as used for this run; command-line overrides:\n"
       << "#   seed: " << config.sim.seed << ", duration: " << config.sim.duration << " s\n"
       << in.rdbuf();
}

std::ofstream OpenOutput(const std::filesystem::path& path) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path.string());
  out.precision(10);
  return out;
}

GroundTruthWriter::GroundTruthWriter(const std::filesystem::path& path) : out_(OpenOutput(path)) {
  out_ << "step,time,id,type,is_ego,x,y,yaw,vx,vy,speed,lateral_speed,yaw_rate,length,width,lane,"
          "x_ego,y_ego,vx_ego,vy_ego\n";
}

void GroundTruthWriter::Write(const sim::Frame& f) {
  const Pose2 ego = f.EgoPose();
  auto row = [&](const sim::VehicleState& v, bool is_ego) {
    const Position p = ego.ToLocal(v.box.center);
    const Velocity vr = ego.RotateToLocal(v.velocity);
    out_ << f.step << ',' << Fixed(f.time, 3) << ',' << v.id << ',' << v.type << ','
         << (is_ego ? 1 : 0) << ',' << Fixed(v.box.center.x(), 4) << ','
         << Fixed(v.box.center.y(), 4) << ',' << Fixed(v.box.yaw, 6) << ','
         << Fixed(v.velocity.x(), 4) << ',' << Fixed(v.velocity.y(), 4) << ',' << Fixed(v.speed, 4)
         << ',' << Fixed(v.lateral_speed, 4) << ',' << Fixed(v.yaw_rate, 6) << ','
         << Fixed(v.box.length, 3) << ',' << Fixed(v.box.width, 3) << ',' << v.lane << ','
         << Fixed(p.x(), 4) << ',' << Fixed(p.y(), 4) << ',' << Fixed(vr.x(), 4) << ','
         << Fixed(vr.y(), 4) << '\n';
  };
  row(f.ego, true);
  for (const auto& v : f.vehicles) row(v, false);
}

DetectionWriter::DetectionWriter(const std::filesystem::path& path) : out_(OpenOutput(path)) {
  out_ << "step,time,sensor,sensor_name,range,azimuth,range_rate,snr_db,x_ego,y_ego,x,y,"
          "radial_speed,vrx,vry,sensor_x,sensor_y,source,is_clutter\n";
}

void DetectionWriter::Write(const Pipeline& p) {
  const auto& f = p.frame();
  for (const auto& d : p.detections()) {
    out_ << f.step << ',' << Fixed(f.time, 3) << ',' << d.sensor << ','
         << p.radar().sensors()[d.sensor].name << ',' << Fixed(d.range, 4) << ','
         << Fixed(d.azimuth, 6) << ',' << Fixed(d.range_rate, 4) << ',' << Fixed(d.snr_db, 2) << ','
         << Fixed(d.position_ego.x(), 4) << ',' << Fixed(d.position_ego.y(), 4) << ','
         << Fixed(d.position_world.x(), 4) << ',' << Fixed(d.position_world.y(), 4) << ','
         << Fixed(d.radial_speed_compensated, 4) << ',' << Fixed(d.radial_velocity_world.x(), 4)
         << ',' << Fixed(d.radial_velocity_world.y(), 4) << ','
         << Fixed(d.sensor_position_world.x(), 4) << ',' << Fixed(d.sensor_position_world.y(), 4)
         << ',' << p.ids().Name(d.source_id) << ',' << (d.is_clutter ? 1 : 0) << '\n';
  }
}

void WriteObstacles(const sim::ScenarioSpec& spec, const std::filesystem::path& path) {
  std::ofstream out = OpenOutput(path);
  out << "id,kind,vertex,x,y,yaw,length,width\n";
  for (const auto& g : spec.guard_rails)
    for (std::size_t i = 0; i < g.points.size(); ++i)
      out << g.id << ",guard_rail," << i << ',' << g.points[i].x() << ',' << g.points[i].y()
          << ",,,\n";
  for (const auto& p : spec.parked)
    out << p.id << ",parked,0," << p.box.center.x() << ',' << p.box.center.y() << ',' << p.box.yaw
        << ',' << p.box.length << ',' << p.box.width << '\n';
}

}  // namespace dualgrid::tools
