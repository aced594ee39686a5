#include "run_outputs.hpp"

#include <cmath>
#include <sstream>

namespace dualgrid::tools {

ClusterWriter::ClusterWriter(const std::filesystem::path& path) : out_(path) {
  out_.buffer() += "step,time,mode,x,y,vx,vy,weight,particles,role,object,x_ego,y_ego\n";
}

void ClusterWriter::Write(const sim::Frame& f, const GridFrame& g, const std::string& mode,
                          const cosim::ModeScorer& scorer,
                          const std::vector<eval::TruthObject>& objects,
                          const cosim::IdRegistry& ids) {
  static const char* kRole[] = {"matched", "duplicate", "false"};
  const auto& a = scorer.association();
  std::ostringstream os;
  os.precision(10);
  for (std::size_t c = 0; c < scorer.clusters().size(); ++c) {
    const eval::Cluster& cl = scorer.clusters()[c];
    const Position pos = g.ToWorld(cl.position);
    const Velocity vel = g.VectorToWorld(cl.velocity);
    const Position local = f.EgoPose().ToLocal(pos);
    os << f.step << ',' << FormatFixed(f.time, 3) << ',' << mode << ',' << FormatFixed(pos.x(), 3)
       << ',' << FormatFixed(pos.y(), 3) << ',' << FormatFixed(vel.x(), 3) << ','
       << FormatFixed(vel.y(), 3) << ',' << cl.weight << ',' << cl.size << ','
       << kRole[static_cast<int>(a.role[c])] << ','
       << (a.object_of_cluster[c] >= 0 ? ids.Name(objects[a.object_of_cluster[c]].id)
                                       : std::string())
       << ',' << FormatFixed(local.x(), 2) << ',' << FormatFixed(local.y(), 2) << '\n';
  }
  out_.buffer() += os.str();
  out_.MaybeFlush();
}

void WeightTraces::Add(const cosim::Pipeline& pipeline, std::size_t mode) {
  const sim::Frame& f = pipeline.frame();
  const auto& grid = pipeline.grid(mode);
  const auto& p = grid.particles();
  const GridFrame& g = pipeline.grid_frame();
  std::set<std::string> in_grid;
  for (const auto& v : f.vehicles) {
    const OrientedBox box = g.ToGrid(v.box);  // particles live in the grid frame
    const Velocity velocity = g.VectorToGrid(v.velocity);
    if (!grid.CellOf(box.center)) continue;
    ++frames_in_grid[v.id];
    in_grid.insert(v.id);
    if (dropped.count(v.id)) continue;
    double wp = 0, wv = 0, w = 0, wp_good = 0, wv_good = 0;
    const BoxTest grown({box.center, box.yaw, box.length + 1.0, box.width + 1.0});
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (!grown.Contains(Position(p.x[i], p.y[i]))) continue;
      wp += p.w_position[i];
      wv += p.w_velocity[i];
      w += p.weight[i];
      if ((Velocity(p.vx[i], p.vy[i]) - velocity).norm() < WeightTrace::kGoodVelocity) {
        wp_good += p.w_position[i];
        wv_good += p.w_velocity[i];
      }
    }
    int n = 0, tangential = 0;
    const int vehicle_id = pipeline.ids().Find(v.id).value_or(-2);  // scanned: registered
    for (const auto& d : pipeline.detections())
      if (d.source_id == vehicle_id) {
        tangential += std::abs(d.radial_speed_compensated) < 0.5 * v.velocity.norm();
        ++n;
      }
    auto& t = by_vehicle[v.id];
    t.time.push_back(f.time);
    t.w_position.push_back(wp);
    t.w_velocity.push_back(wv);
    t.weight.push_back(w);
    t.position_share.push_back(wp > 0 ? wp_good / wp : std::nan(""));
    t.velocity_share.push_back(wv > 0 ? wv_good / wv : std::nan(""));
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

void WriteParticles(const cosim::Pipeline& pipeline, std::size_t m,
                    const cosim::GridSnapshot& snapshot, const std::filesystem::path& path) {
  OutputFile pc(path);
  pc.buffer() += "x,y,vx,vy,w_position,w_velocity,weight,p_dynamic\n";
  const auto& grid = pipeline.grid(m);
  const auto& ps = grid.particles();
  const GridFrame& g = pipeline.grid_frame();
  std::ostringstream os;
  os.precision(10);
  for (std::size_t i = 0; i < ps.size(); ++i) {
    const auto cell = grid.CellOf(Position(ps.x[i], ps.y[i]));
    const double pd =
        cell ? snapshot.dynamic[static_cast<std::size_t>(cell->y) * snapshot.cells_x + cell->x]
             : 0.0;
    // Written in the world frame, like every other file of the run.
    const Position pos = g.ToWorld(Position(ps.x[i], ps.y[i]));
    const Velocity vel = g.VectorToWorld(Velocity(ps.vx[i], ps.vy[i]));
    os << FormatFixed(pos.x(), 3) << ',' << FormatFixed(pos.y(), 3) << ','
       << FormatFixed(vel.x(), 3) << ',' << FormatFixed(vel.y(), 3) << ',' << ps.w_position[i]
       << ',' << ps.w_velocity[i] << ',' << ps.weight[i] << ',' << FormatFixed(pd, 3) << '\n';
  }
  pc.buffer() += os.str();
  pc.Close();
}

void WriteObjects(const std::vector<std::string>& modes,
                  const std::vector<eval::ScenarioMetrics>& metrics, const cosim::IdRegistry& ids,
                  const std::filesystem::path& path,
                  const std::map<std::string, std::string>* categories) {
  std::ostringstream os;
  os << "mode,id,name,frames_in_grid,frames_tracked,frames_tracked_v,scored,D,D_v,t_d,delta_x,"
        "delta_v"
     << (categories ? ",category\n" : "\n");
  auto opt = [](const std::optional<double>& v) { return v ? FormatFixed(*v, 4) : std::string(); };
  auto category = [&](const std::string& name) {
    if (!categories) return std::string();
    const auto it = categories->find(name);
    return "," + (it != categories->end() ? it->second : std::string());
  };
  for (std::size_t m = 0; m < modes.size(); ++m)
    for (const auto& o : metrics[m].objects)
      os << modes[m] << ',' << o.id << ',' << ids.Name(o.id) << ',' << o.frames_in_grid << ','
         << o.frames_tracked << ',' << o.frames_tracked_v << ',' << (o.scored ? 1 : 0) << ','
         << opt(o.tracked_fraction) << ',' << opt(o.tracked_fraction_v) << ','
         << opt(o.detection_time) << ',' << opt(o.position_error) << ',' << opt(o.velocity_error)
         << category(ids.Name(o.id)) << '\n';
  WriteTextFile(path, os.str());
}

void WriteWeights(const WeightTrace& t, const std::string& object,
                  const std::filesystem::path& path) {
  std::ostringstream os;
  os.precision(10);
  os << "time,object,w_position,w_velocity,w_resample,position_share,velocity_share,"
        "tangential_share\n";
  for (std::size_t i = 0; i < t.time.size(); ++i)
    os << FormatFixed(t.time[i], 3) << ',' << object << ',' << t.w_position[i] << ','
       << t.w_velocity[i] << ',' << t.weight[i] << ',' << t.position_share[i] << ','
       << t.velocity_share[i] << ',' << t.tangential_share[i] << '\n';
  WriteTextFile(path, os.str());
}

void WriteTables(const eval::ComparisonTable& table, const std::filesystem::path& dir) {
  WriteTextFile(dir / "table.md", table.ToMarkdown());
  WriteTextFile(dir / "table.csv", table.ToCsv());
  WriteTextFile(dir / "table.json", table.ToJson().dump(2) + "\n");
}

std::vector<std::string> UnscoredNotes(const std::vector<eval::ScenarioMetrics>& metrics,
                                       const cosim::IdRegistry& ids, int min_frames_in_grid) {
  // Every mode sees the same vehicles in the same grid: the first mode's objects suffice.
  if (metrics.empty()) return {};
  std::string list;
  int count = 0;
  for (const auto& o : metrics.front().objects) {
    if (o.scored) continue;
    if (++count <= 12)
      list += (list.empty() ? "" : ", ") + ids.Name(o.id) + " (" +
              std::to_string(o.frames_in_grid) + ")";
  }
  if (count == 0) return {};
  if (count > 12) list += ", and " + std::to_string(count - 12) + " more";
  return {"Not scored, fewer than " + std::to_string(min_frames_in_grid) +
          " frames in the grid (`evaluation.min_frames_in_grid`): " + list +
          ". Their frames are in objects.csv."};
}

}  // namespace dualgrid::tools
